#include "gbdcs/sim/renderer.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "option_reader.hpp"
#include "osmesa_context.hpp"

namespace gbdcs::sim {
namespace {

constexpr int kMaxSide = 8192;

void check_options(const RendererOptions& options) {
  if (options.width < 1 || options.width > kMaxSide || options.height < 1 ||
      options.height > kMaxSide) {
    throw std::invalid_argument("Renderer: the image size must be 1 ... " +
                                std::to_string(kMaxSide) + " pixels a side, got " +
                                std::to_string(options.width) + "x" +
                                std::to_string(options.height));
  }
  if (options.multisamples < 0 || options.multisamples > 16) {
    throw std::invalid_argument("Renderer: multisamples must be 0 ... 16, got " +
                                std::to_string(options.multisamples));
  }
}

std::string camera_name(const mjModel* model, int id) {
  const char* name = mj_id2name(model, mjOBJ_CAMERA, id);
  return (name != nullptr && name[0] != '\0') ? std::string(name) : "#" + std::to_string(id);
}

}  // namespace

RendererOptions RendererOptions::from_json(const nlohmann::json& doc) {
  RendererOptions options;
  detail::OptionReader reader(doc, "RendererOptions");
  reader.read("width", options.width);
  reader.read("height", options.height);
  reader.read("shadows", options.shadows);
  reader.read("reflections", options.reflections);
  reader.read("multisamples", options.multisamples);
  reader.finish();
  check_options(options);
  return options;
}

struct Renderer::Impl {
  Impl(const mjModel* m, RendererOptions o) : model(m), options(o), gl(o.width, o.height) {
    // mjr_makeContext sizes its off-screen framebuffer from the model's visual settings. The
    // model is const and shared, so hand it a shallow copy (same arrays) with our settings.
    mjModel sized = *model;
    sized.vis.global.offwidth = options.width;
    sized.vis.global.offheight = options.height;
    sized.vis.quality.offsamples = options.multisamples;
    mjv_defaultOption(&scene_options);
    mjv_defaultCamera(&camera);
    mjv_defaultScene(&scene);
    mjr_defaultContext(&context);
    mjv_makeScene(model, &scene, std::max(1000, 2 * model->ngeom + 200));
    mjr_makeContext(&sized, &context, mjFONTSCALE_100);
    mjr_setBuffer(mjFB_OFFSCREEN, &context);
    if (context.currentBuffer != mjFB_OFFSCREEN) {
      free_resources();
      throw std::runtime_error("Renderer: the OSMesa context has no off-screen framebuffer");
    }
    rgb.create(options.height, options.width, CV_8UC3);
  }

  ~Impl() {
    if (gl.on_owner_thread()) {
      gl.make_current();
      free_resources();
    } else {
      // GL objects cannot be freed from here; destroying the context releases them.
      mjv_freeScene(&scene);
    }
  }

  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void free_resources() {
    mjr_freeContext(&context);
    mjv_freeScene(&scene);
  }

  int camera_id(std::string_view name) const {
    const int id = mj_name2id(model, mjOBJ_CAMERA, std::string(name).c_str());
    if (id >= 0) {
      return id;
    }
    std::ostringstream message;
    message << "Renderer: no camera '" << name << "' in the model; its cameras: ";
    if (model->ncam == 0) {
      message << "(none)";
    }
    for (int i = 0; i < model->ncam; ++i) {
      message << (i > 0 ? ", " : "") << camera_name(model, i);
    }
    throw std::invalid_argument(message.str());
  }

  const mjModel* model;
  RendererOptions options;
  detail::OsMesaContext gl;
  mjvOption scene_options{};
  mjvCamera camera{};
  mjvScene scene{};
  mjrContext context{};
  cv::Mat rgb;
};

Renderer::Renderer(const mjModel* model, RendererOptions options) {
  if (model == nullptr) {
    throw std::invalid_argument("Renderer: the model is null");
  }
  check_options(options);
  impl_ = std::make_unique<Impl>(model, options);
}

Renderer::~Renderer() = default;

cv::Mat Renderer::render(const mjData* data, std::string_view camera) {
  if (data == nullptr) {
    throw std::invalid_argument("Renderer: the state (mjData) is null");
  }
  Impl& r = *impl_;
  r.gl.make_current();
  r.camera.type = mjCAMERA_FIXED;
  r.camera.fixedcamid = r.camera_id(camera);
  // mjv_updateScene takes mjData* for historical reasons but only reads it (the test
  // Renderer.LeavesTheStateUntouched holds that).
  mjv_updateScene(r.model, const_cast<mjData*>(data), &r.scene_options, nullptr, &r.camera,
                  mjCAT_ALL, &r.scene);
  r.scene.flags[mjRND_SHADOW] = r.options.shadows ? 1 : 0;
  r.scene.flags[mjRND_REFLECTION] = r.options.reflections ? 1 : 0;

  const mjrRect viewport{0, 0, r.options.width, r.options.height};
  mjr_setBuffer(mjFB_OFFSCREEN, &r.context);
  mjr_render(viewport, &r.scene, &r.context);
  mjr_readPixels(r.rgb.data, nullptr, viewport, &r.context);

  cv::Mat bgr;
  cv::cvtColor(r.rgb, bgr, cv::COLOR_RGB2BGR);
  cv::flip(bgr, bgr, 0);  // GL's first row is the bottom one
  return bgr;
}

std::vector<std::string> Renderer::camera_names() const {
  std::vector<std::string> names;
  for (int i = 0; i < impl_->model->ncam; ++i) {
    names.push_back(camera_name(impl_->model, i));
  }
  return names;
}

const RendererOptions& Renderer::options() const {
  return impl_->options;
}

const mjModel* Renderer::model() const {
  return impl_->model;
}

RenderTiming measure_render(Renderer& renderer, const mjData* data, std::string_view camera,
                            int frames, int warmup) {
  if (frames < 1) {
    throw std::invalid_argument("measure_render: frames must be at least 1");
  }
  for (int i = 0; i < warmup; ++i) {
    renderer.render(data, camera);
  }
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(frames));
  const std::clock_t cpu_start = std::clock();
  for (int i = 0; i < frames; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const cv::Mat image = renderer.render(data, camera);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  std::sort(ms.begin(), ms.end());
  const auto at = [&ms](double q) {
    return ms[std::min(ms.size() - 1,
                       static_cast<std::size_t>(q * static_cast<double>(ms.size())))];
  };
  return RenderTiming{frames, at(0.5), at(0.9), ms.back(), cpu_ms / frames};
}

}  // namespace gbdcs::sim
