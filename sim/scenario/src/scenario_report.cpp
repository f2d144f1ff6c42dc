#include "gbdcs/sim/scenario_report.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace gbdcs::sim {

namespace {

std::string fixed(double v, int decimals) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

std::string xml_escape(const std::string& in) {
  std::string out;
  for (char c : in) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        // XML 1.0 forbids most control characters.
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\n' || c == '\t') out += c;
    }
  }
  return out;
}

bool failed(const ScenarioResult& r) { return !r.passed || !r.error.empty(); }

// Splits text into lines of at most `width` characters, breaking at spaces where it can.
std::vector<std::string> wrap(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::string rest = text;
  while (rest.size() > width) {
    auto cut = rest.rfind(' ', width);
    if (cut == std::string::npos || cut == 0) cut = width;
    lines.push_back(rest.substr(0, cut));
    rest = rest.substr(cut == width ? cut : cut + 1);
  }
  lines.push_back(rest);
  return lines;
}

}  // namespace

std::string progress_line(const ScenarioResult& r) {
  std::ostringstream s;
  s << (failed(r) ? "FAIL  " : "PASS  ") << r.name;
  if (!r.error.empty() && r.criteria.empty()) {
    s << "  (error: " << r.error << ")";
    return s.str();
  }
  const auto failures = std::count_if(r.criteria.begin(), r.criteria.end(),
                                      [](const auto& c) { return c.verdict == Verdict::kFailure; });
  s << "  (" << r.criteria.size() << " criteria";
  if (failures > 0) s << ", " << failures << " failed";
  s << ", " << fixed(r.sim_s, 1) << " sim-s in " << fixed(r.wall_s, 2) << " s";
  if (r.wall_s > 0) s << ", " << fixed(r.sim_s / r.wall_s, 0) << "x real time";
  s << ")";
  if (!r.error.empty()) s << " error: " << r.error;
  return s.str();
}

nlohmann::json report_json(const std::vector<ScenarioResult>& results, double wall_s) {
  nlohmann::json out;
  out["scenarios"] = nlohmann::json::array();
  int passed = 0;
  for (const auto& r : results) {
    nlohmann::json j;
    j["name"] = r.name;
    j["path"] = r.path;
    j["description"] = r.description;
    j["drone"] = r.drone;
    j["camera"] = r.camera;
    j["passed"] = !failed(r);
    j["error"] = r.error;
    j["sim_s"] = r.sim_s;
    j["wall_s"] = r.wall_s;
    j["realtime_factor"] = r.wall_s > 0 ? r.sim_s / r.wall_s : 0.0;
    j["criteria"] = nlohmann::json::array();
    for (const auto& c : r.criteria) {
      j["criteria"].push_back({{"name", c.name},
                               {"type", std::string(to_string(c.type))},
                               {"expected", c.expected},
                               {"actual", c.actual},
                               {"result", std::string(to_string(c.verdict))}});
    }
    j["artifacts"] = r.artifacts;
    out["scenarios"].push_back(j);
    if (!failed(r)) ++passed;
  }
  out["passed"] = passed;
  out["failed"] = static_cast<int>(results.size()) - passed;
  out["wall_s"] = wall_s;
  return out;
}

std::string report_junit(const std::vector<ScenarioResult>& results, double wall_s) {
  std::ostringstream x;
  std::size_t tests = 0, failures = 0, errors = 0;
  for (const auto& r : results) {
    if (!r.error.empty() && r.criteria.empty()) {
      ++tests;
      ++errors;
      continue;
    }
    tests += r.criteria.size();
    failures += static_cast<std::size_t>(
        std::count_if(r.criteria.begin(), r.criteria.end(),
                      [](const auto& c) { return c.verdict == Verdict::kFailure; }));
    if (!r.error.empty()) ++errors;
  }
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x << "<testsuites name=\"gbdcs scenarios\" tests=\"" << tests << "\" failures=\"" << failures
    << "\" errors=\"" << errors << "\" time=\"" << fixed(wall_s, 3) << "\">\n";
  for (const auto& r : results) {
    const auto suite_failures = std::count_if(
        r.criteria.begin(), r.criteria.end(),
        [](const auto& c) { return c.verdict == Verdict::kFailure; });
    x << "  <testsuite name=\"" << xml_escape(r.name) << "\" tests=\""
      << std::max<std::size_t>(r.criteria.size(), 1) << "\" failures=\"" << suite_failures
      << "\" errors=\"" << (r.error.empty() ? 0 : 1) << "\" time=\"" << fixed(r.wall_s, 3)
      << "\" file=\"" << xml_escape(r.path) << "\">\n";
    x << "    <properties>\n";
    x << "      <property name=\"drone\" value=\"" << xml_escape(r.drone) << "\"/>\n";
    x << "      <property name=\"camera\" value=\"" << xml_escape(r.camera) << "\"/>\n";
    x << "      <property name=\"sim_s\" value=\"" << fixed(r.sim_s, 3) << "\"/>\n";
    x << "    </properties>\n";
    if (!r.error.empty() && r.criteria.empty()) {
      x << "    <testcase classname=\"scenario." << xml_escape(r.name)
        << "\" name=\"load\" time=\"0\">\n      <error message=\"" << xml_escape(r.error)
        << "\"/>\n    </testcase>\n";
    }
    for (const auto& c : r.criteria) {
      x << "    <testcase classname=\"scenario." << xml_escape(r.name) << "\" name=\""
        << xml_escape(c.name) << "\" time=\"0\">\n";
      const std::string text = "expected: " + c.expected + "\nactual: " + c.actual +
                               "\nresult: " + std::string(to_string(c.verdict));
      if (c.verdict == Verdict::kFailure) {
        x << "      <failure message=\"" << xml_escape(c.name + ": expected " + c.expected +
                                                       ", actual " + c.actual)
          << "\" type=\"" << to_string(c.type) << "\">" << xml_escape(text) << "</failure>\n";
      } else {
        x << "      <system-out>" << xml_escape(text) << "</system-out>\n";
      }
      x << "    </testcase>\n";
    }
    if (!r.artifacts.empty()) {
      x << "    <system-out>artifacts:";
      for (const auto& a : r.artifacts) x << " " << xml_escape(a);
      x << "</system-out>\n";
    }
    x << "  </testsuite>\n";
  }
  x << "</testsuites>\n";
  return x.str();
}

void print_table(std::ostream& out, const std::vector<ScenarioResult>& results, int width) {
  std::size_t w_scen = 8, w_crit = 9;
  for (const auto& r : results) {
    w_scen = std::max(w_scen, r.name.size());
    for (const auto& c : r.criteria) w_crit = std::max(w_crit, c.name.size());
  }
  w_scen = std::min<std::size_t>(w_scen, 34);
  w_crit = std::min<std::size_t>(w_crit, 28);
  const std::size_t w_res = 10;
  const std::size_t rest = static_cast<std::size_t>(std::max(width, 100)) - w_scen - w_crit -
                           w_res - 8;
  const std::size_t w_exp = rest * 2 / 5, w_act = rest - w_exp;
  auto row = [&](const std::string& a, const std::string& b, const std::string& c,
                 const std::string& d, const std::string& e) {
    auto ca = wrap(a, w_scen), cb = wrap(b, w_crit), cc = wrap(c, w_exp), cd = wrap(d, w_act);
    const auto n = std::max({ca.size(), cb.size(), cc.size(), cd.size()});
    for (std::size_t i = 0; i < n; ++i) {
      auto at = [&](const std::vector<std::string>& v) { return i < v.size() ? v[i] : ""; };
      out << std::left << std::setw(static_cast<int>(w_scen)) << at(ca) << "  "
          << std::setw(static_cast<int>(w_crit)) << at(cb) << "  "
          << std::setw(static_cast<int>(w_exp)) << at(cc) << "  "
          << std::setw(static_cast<int>(w_act)) << at(cd) << "  " << (i == 0 ? e : "") << "\n";
    }
  };
  row("scenario", "criterion", "expected", "actual", "result");
  out << std::string(static_cast<std::size_t>(std::max(width, 100)), '-') << "\n";
  for (const auto& r : results) {
    if (!r.error.empty() && r.criteria.empty()) {
      row(r.name, "(load/run)", "the scenario runs", r.error, "ERROR");
      continue;
    }
    for (const auto& c : r.criteria) {
      row(r.name, c.name, c.expected, c.actual, std::string(to_string(c.verdict)));
    }
    if (!r.error.empty()) row(r.name, "(artifacts)", "written", r.error, "ERROR");
  }
  const auto passed = std::count_if(results.begin(), results.end(),
                                    [](const auto& r) { return !failed(r); });
  out << std::string(static_cast<std::size_t>(std::max(width, 100)), '-') << "\n";
  out << passed << " of " << results.size() << " scenarios passed\n";
}

}  // namespace gbdcs::sim
