// Renderer: draws a MuJoCo state from one of the model's cameras into an OpenCV image, off
// screen, on the CPU (OSMesa / llvmpipe): no display, no GPU.
//
// Model apart from state: a Renderer is built for one model (`const mjModel*`, which must
// outlive it; its meshes and textures are uploaded once) and renders any state (`mjData`) of
// that model.
//
// Inputs   render(data, camera): a state of the model (kinematics computed, e.g. after
//          mj_forward or mj_step) and a camera name from the model ("chase", "onboard", ...).
//          The state is only read.
// Output   CV_8UC3, BGR, options.width x options.height, top row first (the GL image flipped).
// Options  RendererOptions (JSON: the same keys)
//            width, height  pixels; default 640 x 480; 1 ... 8192
//            shadows        default false: shadow maps cost an extra pass per light on the CPU
//            reflections    default false: reflective floors cost an extra pass
//            multisamples   anti-aliasing samples, default 0 (off): on llvmpipe 4 samples make a
//                           640x480 frame about 5x slower; 0 ... 16 (overrides the model's
//                           <quality offsamples>)
// Errors   unknown camera -> std::invalid_argument listing the model's cameras; a null model
//          or state, or a bad size -> std::invalid_argument; OSMesa cannot make a context ->
//          std::runtime_error naming the OSMesa call.
//
// Threading rule: each Renderer owns one OSMesa GL context, bound to the thread that
// constructed it. Construct, render() and destroy it on that one thread; render() from any
// other thread throws std::logic_error. Several Renderers may live on one thread (render()
// makes its own context current). The state must not be stepped by another thread while
// render() reads it: render the twin between steps, or render a copy (mj_copyData).
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace gbdcs::sim {

struct RendererOptions {
  int width = 640;
  int height = 480;
  bool shadows = false;
  bool reflections = false;
  int multisamples = 0;

  // Absent keys keep their defaults; an unknown key or a wrong type throws
  // std::invalid_argument naming the key.
  static RendererOptions from_json(const nlohmann::json& doc);
};

class Renderer {
 public:
  explicit Renderer(const mjModel* model, RendererOptions options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  cv::Mat render(const mjData* data, std::string_view camera);

  std::vector<std::string> camera_names() const;  // in model order; unnamed: "#<id>"
  const RendererOptions& options() const;
  const mjModel* model() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Render timing of one camera, for `gbdcs bench twin` and docs/PERFORMANCE.md.
struct RenderTiming {
  int frames = 0;
  double p50_ms = 0;
  double p90_ms = 0;
  double max_ms = 0;
  // Process CPU time per render (this thread and llvmpipe's rasteriser threads), mean: the
  // figure that does not depend on what else the machine is running.
  double cpu_ms_mean = 0;
};

// Renders `frames` times (after `warmup` untimed renders) on the calling thread and reports
// wall-clock milliseconds per render() call, including the read-back and the BGR flip, and
// the process CPU time they took.
RenderTiming measure_render(Renderer& renderer, const mjData* data, std::string_view camera,
                            int frames = 50, int warmup = 3);

}  // namespace gbdcs::sim
