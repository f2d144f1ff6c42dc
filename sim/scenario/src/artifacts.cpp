// A run's artifacts: the event log, the trajectory plot and the side-by-side video.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/sim/renderer.hpp"
#include "gbdcs/sim/trajectory_plot.hpp"
#include "gbdcs/sim/video_recorder.hpp"
#include "runner_parts.hpp"

namespace gbdcs::sim::detail {

namespace {

namespace fs = std::filesystem;

constexpr int kPanelW = 320;
constexpr int kPanelH = 240;

std::string fixed(double v, int decimals) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

void write_log(const fs::path& path, const RunRecord& r, const std::vector<LoggedEvent>& events) {
  std::vector<std::pair<double, nlohmann::json>> lines;
  for (const auto& e : events) {
    lines.push_back({e.t_s, {{"t_s", e.t_s}, {"kind", "event"}, {"event", e.description}}});
  }
  for (const auto& g : r.gestures) {
    lines.push_back({g.t_s, {{"t_s", g.t_s}, {"kind", "gesture"}, {"data", contracts::to_json(g.event)}}});
  }
  for (const auto& c : r.commands) {
    nlohmann::json j = {{"t_s", c.t_s}, {"kind", "command"}, {"data", contracts::to_json(c.command)},
                        {"outcome", c.outcome}};
    if (c.processing_ms >= 0) j["processing_ms"] = c.processing_ms;
    lines.push_back({c.t_s, j});
  }
  for (const auto& a : r.alerts) {
    lines.push_back({a.t_s, {{"t_s", a.t_s}, {"kind", "alert"}, {"data", contracts::to_json(a.alert)}}});
  }
  for (const auto& t : r.telemetry) {
    lines.push_back(
        {t.t_s, {{"t_s", t.t_s}, {"kind", "telemetry"}, {"data", contracts::to_json(t.frame)}}});
  }
  std::stable_sort(lines.begin(), lines.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  for (const auto& [t, j] : lines) out << j.dump() << "\n";
}

void write_plot(const fs::path& path, const Scenario& s, const RunRecord& r) {
  std::vector<TrajectorySample> samples;
  for (const auto& t : r.telemetry) {
    samples.push_back({t.t_s, t.frame.x_m, t.frame.y_m, t.frame.altitude_m, t.frame.heading_deg,
                       t.frame.battery_pct});
  }
  if (samples.empty()) return;
  PlotOptions po;
  po.title = "scenario " + s.name;
  TrajectoryPlot plot;
  plot.draw(samples, po);
  plot.save(path);
}

// MediaPipe's hand connections.
constexpr std::array<std::pair<int, int>, 21> kBones{{{0, 1},   {1, 2},   {2, 3},   {3, 4},
                                                       {0, 5},   {5, 6},   {6, 7},   {7, 8},
                                                       {5, 9},   {9, 10},  {10, 11}, {11, 12},
                                                       {9, 13},  {13, 14}, {14, 15}, {15, 16},
                                                       {13, 17}, {17, 18}, {18, 19}, {19, 20},
                                                       {0, 17}}};

cv::Mat hand_panel(const VideoSnapshot& v) {
  cv::Mat panel;
  if (!v.jpeg.empty()) {
    panel = cv::imdecode(v.jpeg, cv::IMREAD_COLOR);
    cv::resize(panel, panel, cv::Size(kPanelW, kPanelH));
  } else {
    panel = cv::Mat(kPanelH, kPanelW, CV_8UC3, cv::Scalar(40, 36, 32));
  }
  if (v.hand) {  // the timeline's landmarks, or what the tracker found on the pixels
    auto px = [&](std::size_t i) {
      return cv::Point(static_cast<int>(v.hand->points[i].x * kPanelW),
                       static_cast<int>(v.hand->points[i].y * kPanelH));
    };
    for (const auto& [a, b] : kBones) {
      cv::line(panel, px(static_cast<std::size_t>(a)), px(static_cast<std::size_t>(b)),
               cv::Scalar(200, 220, 235), 2, cv::LINE_AA);
    }
    for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
      cv::circle(panel, px(i), 3, cv::Scalar(60, 160, 255), cv::FILLED, cv::LINE_AA);
    }
  }
  const auto colour = cv::Scalar(255, 255, 255);
  cv::putText(panel, "hand: " + v.label, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45, colour, 1,
              cv::LINE_AA);
  if (v.vision_down) {
    cv::putText(panel, "VISION DOWN", {8, 40}, cv::FONT_HERSHEY_SIMPLEX, 0.6,
                cv::Scalar(60, 60, 255), 2, cv::LINE_AA);
  }
  return panel;
}

// Places the free joint from telemetry, for drones without physics (the dummy).
std::vector<double> qpos_from_telemetry(const TwinModel& model, const contracts::TelemetryFrame& f) {
  const double yaw = -f.heading_deg * M_PI / 180.0;  // MuJoCo: counter-clockwise, y left
  return {f.x_m, -f.y_m, model.rest_height_m() + f.altitude_m, std::cos(yaw / 2), 0, 0,
          std::sin(yaw / 2)};
}

void write_video(const fs::path& path, const std::vector<VideoSnapshot>& video, double fps,
                 const TwinModel& model) {
  if (video.empty()) return;
  const mjModel* m = model.mj_model();
  RendererOptions ro;
  ro.width = kPanelW;
  ro.height = kPanelH;
  Renderer renderer(m, ro);
  mjData* d = mj_makeData(m);
  VideoRecorderOptions vo;
  vo.fps = fps;
  VideoRecorder recorder(path, cv::Size(2 * kPanelW, kPanelH), vo);
  const int adr = model.free_joint_qpos_address();
  try {
    for (const auto& v : video) {
      std::vector<double> q = v.qpos;
      if (q.empty() && v.telemetry) q = qpos_from_telemetry(model, *v.telemetry);
      if (q.size() == 7) std::copy(q.begin(), q.end(), d->qpos + adr);
      mj_forward(m, d);
      cv::Mat drone = renderer.render(d, "chase");
      const auto white = cv::Scalar(255, 255, 255);
      cv::putText(drone, "t " + fixed(v.t_s, 1) + " s", {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                  white, 1, cv::LINE_AA);
      if (v.telemetry) {
        cv::putText(drone,
                    std::string(contracts::to_string(v.telemetry->flight_state)) + "  alt " +
                        fixed(v.telemetry->altitude_m, 2) + " m  bat " +
                        fixed(v.telemetry->battery_pct, 0) + " %",
                    {8, 36}, cv::FONT_HERSHEY_SIMPLEX, 0.45, white, 1, cv::LINE_AA);
      }
      if (!v.last_command.empty()) {
        cv::putText(drone, v.last_command, {8, kPanelH - 28}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
                    white, 1, cv::LINE_AA);
      }
      if (!v.last_alert.empty()) {
        cv::putText(drone, v.last_alert, {8, kPanelH - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
                    cv::Scalar(80, 180, 255), 1, cv::LINE_AA);
      }
      cv::Mat both;
      cv::hconcat(drone, hand_panel(v), both);
      recorder.write(both);
    }
  } catch (...) {
    mj_deleteData(d);
    throw;
  }
  mj_deleteData(d);
  recorder.close();
}

}  // namespace

std::vector<std::string> write_artifacts(const std::string& dir, const Scenario& scenario,
                                         const RunRecord& record,
                                         const std::vector<LoggedEvent>& events,
                                         const std::vector<VideoSnapshot>& video,
                                         double video_fps, const TwinModel& model) {
  fs::create_directories(dir);
  std::vector<std::string> files;
  const auto log = fs::path(dir) / "events.jsonl";
  write_log(log, record, events);
  files.push_back(log.string());
  if (!record.telemetry.empty()) {
    const auto plot = fs::path(dir) / "trajectory.png";
    write_plot(plot, scenario, record);
    files.push_back(plot.string());
  }
  if (!video.empty()) {
    const auto mp4 = fs::path(dir) / "video.mp4";
    write_video(mp4, video, video_fps, model);
    files.push_back(mp4.string());
  }
  return files;
}

}  // namespace gbdcs::sim::detail
