// The dashboard's files (web/dist): GET/HEAD only, MIME type by extension, nothing outside
// the folder (no "..", backslashes, NULs or symlinks escaping it), index.html for client-side
// routes, and a page saying how to build the dashboard when the folder is missing.
#pragma once

#include <string>

#include "api.hpp"

namespace gbdcs::server {

std::string mime_type(const std::string& path);
// path: the URL path, already percent-decoded. Throws ApiError 404.
ApiResponse serve_static(const std::string& web_dir, const std::string& path);
std::string percent_decode(std::string_view text, bool plus_is_space);

}  // namespace gbdcs::server
