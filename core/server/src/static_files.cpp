#include "static_files.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace gbdcs::server {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kPlaceholder = R"(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>GBDCS server</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 3em auto">
<h1>GBDCS server is running</h1>
<p>The dashboard is not built, so there is nothing to show here yet.</p>
<p>Build it with <code>cd web &amp;&amp; npm ci &amp;&amp; npm run build</code> (it lands in
<code>web/dist</code>), or point the server at it with <code>gbdcs serve --web DIR</code>.</p>
<p>The API works without it: <a href="/api/v1/healthz">/api/v1/healthz</a>,
<a href="/api/v1/openapi.json">/api/v1/openapi.json</a>, <a href="/metrics">/metrics</a>;
live data on <code>/ws/live?token=...</code> (docs/API.md).</p>
</body></html>
)";

[[noreturn]] void not_found(const std::string& path) {
  throw ApiError(404, "not_found", "there is no file " + path.substr(0, 200),
                 "check the address; the dashboard starts at /");
}

}  // namespace

std::string percent_decode(std::string_view text, bool plus_is_space) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '%' && i + 2 < text.size() && std::isxdigit(static_cast<unsigned char>(text[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(text[i + 2]))) {
      out += static_cast<char>(std::stoi(std::string(text.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else if (c == '+' && plus_is_space) {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out;
}

std::string mime_type(const std::string& path) {
  const auto ext = fs::path(path).extension().string();
  static const std::pair<const char*, const char*> kTypes[] = {
      {".html", "text/html; charset=utf-8"},  {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"}, {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},    {".json", "application/json"},
      {".map", "application/json"},           {".svg", "image/svg+xml"},
      {".png", "image/png"},                  {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},                {".gif", "image/gif"},
      {".webp", "image/webp"},                {".ico", "image/vnd.microsoft.icon"},
      {".woff", "font/woff"},                 {".woff2", "font/woff2"},
      {".ttf", "font/ttf"},                   {".txt", "text/plain; charset=utf-8"},
      {".wasm", "application/wasm"},          {".webmanifest", "application/manifest+json"}};
  for (const auto& [e, t] : kTypes) {
    if (ext == e) return t;
  }
  return "application/octet-stream";
}

ApiResponse serve_static(const std::string& web_dir, const std::string& path) {
  if (path.find("..") != std::string::npos || path.find('\\') != std::string::npos ||
      path.find('\0') != std::string::npos || path.empty() || path.front() != '/') {
    not_found(path);
  }
  std::error_code ec;
  const auto root = fs::canonical(web_dir, ec);
  if (ec || !fs::is_directory(root)) {
    if (path == "/" || path == "/index.html") {
      ApiResponse r;
      r.body = std::string(kPlaceholder);
      r.content_type = "text/html; charset=utf-8";
      return r;
    }
    not_found(path);
  }
  auto rel = path.substr(1);
  fs::path file = rel.empty() ? root / "index.html" : root / rel;
  if (!fs::is_regular_file(file, ec)) {
    // Client-side routes (no extension) get the app; a missing asset is a 404.
    if (fs::path(rel).has_extension()) not_found(path);
    file = root / "index.html";
  }
  const auto real = fs::canonical(file, ec);
  if (ec) not_found(path);
  const auto root_s = root.string() + "/";
  if (real.string().compare(0, root_s.size(), root_s) != 0) not_found(path);
  std::ifstream in(real, std::ios::binary);
  if (!in) not_found(path);
  std::ostringstream data;
  data << in.rdbuf();
  ApiResponse r;
  r.body = data.str();
  r.content_type = mime_type(real.string());
  r.headers.emplace_back("X-Content-Type-Options", "nosniff");
  return r;
}

}  // namespace gbdcs::server
