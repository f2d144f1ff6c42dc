#include "osmesa_context.hpp"

#include <GL/osmesa.h>

#include <sstream>
#include <stdexcept>
#include <string>

namespace gbdcs::sim::detail {
namespace {

OSMesaContext as_osmesa(void* context) {
  return static_cast<OSMesaContext>(context);
}

}  // namespace

OsMesaContext::OsMesaContext(int width, int height)
    : width_(width), height_(height), owner_(std::this_thread::get_id()) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("OSMesa: the buffer size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  // 24-bit depth, 8-bit stencil (MuJoCo's shadows and reflections use the stencil), no accum.
  OSMesaContext context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (context == nullptr) {
    throw std::runtime_error(
        "OSMesa: OSMesaCreateContextExt(OSMESA_RGBA, depth 24, stencil 8) failed; is the "
        "Mesa software driver installed (Debian: libosmesa6)?");
  }
  context_ = context;
  buffer_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
  if (OSMesaMakeCurrent(context, buffer_.data(), GL_UNSIGNED_BYTE, width, height) == 0) {
    OSMesaDestroyContext(context);
    context_ = nullptr;
    std::ostringstream message;
    message << "OSMesa: OSMesaMakeCurrent failed for a " << width << "x" << height
            << " RGBA buffer";
    throw std::runtime_error(message.str());
  }
}

OsMesaContext::~OsMesaContext() {
  if (context_ == nullptr) {
    return;
  }
  if (OSMesaGetCurrentContext() == as_osmesa(context_)) {
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);  // unbind before destroying
  }
  OSMesaDestroyContext(as_osmesa(context_));
}

void OsMesaContext::make_current() {
  if (!on_owner_thread()) {
    throw std::logic_error(
        "OSMesa: a Renderer must be used on the thread that created it (its GL context is "
        "bound to that thread)");
  }
  if (OSMesaGetCurrentContext() == as_osmesa(context_)) {
    return;
  }
  if (OSMesaMakeCurrent(as_osmesa(context_), buffer_.data(), GL_UNSIGNED_BYTE, width_, height_) ==
      0) {
    throw std::runtime_error("OSMesa: OSMesaMakeCurrent failed when switching contexts");
  }
}

}  // namespace gbdcs::sim::detail
