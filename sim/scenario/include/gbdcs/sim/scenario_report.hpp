// Reports of a scenario run: the console table, JUnit XML (one <testsuite> per scenario, one
// <testcase> per criterion, so CI shows which criterion failed and why) and JSON.
//
// JSON: {"scenarios": [{"name", "path", "description", "drone", "camera", "passed", "error",
//        "sim_s", "wall_s", "realtime_factor", "criteria": [{"name", "type", "expected",
//        "actual", "result"}], "artifacts": [...]}], "passed": n, "failed": n, "wall_s": s}
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "gbdcs/sim/scenario_runner.hpp"

namespace gbdcs::sim {

nlohmann::json report_json(const std::vector<ScenarioResult>& results, double wall_s);
std::string report_junit(const std::vector<ScenarioResult>& results, double wall_s);
// scenario | criterion | expected | actual | result, columns wrapped to `width` characters.
void print_table(std::ostream& out, const std::vector<ScenarioResult>& results, int width = 160);
// "PASS  idle_hover  (4 criteria, 12.0 sim-s in 0.21 s, 57x real time)"
std::string progress_line(const ScenarioResult& result);

}  // namespace gbdcs::sim
