// OsMesaContext: one software (llvmpipe) OpenGL context with its own RGBA colour buffer,
// created and made current on the constructing thread. Private to sim/render.
#pragma once

#include <thread>
#include <vector>

namespace gbdcs::sim::detail {

class OsMesaContext {
 public:
  // Throws std::runtime_error naming the failing OSMesa call (no libOSMesa driver, out of
  // memory, bad size). Leaves the context current on this thread.
  OsMesaContext(int width, int height);
  ~OsMesaContext();
  OsMesaContext(const OsMesaContext&) = delete;
  OsMesaContext& operator=(const OsMesaContext&) = delete;

  // Makes this context current on the calling thread (a no-op when it already is); throws
  // std::logic_error when called from a thread other than the one that created it.
  void make_current();
  bool on_owner_thread() const { return std::this_thread::get_id() == owner_; }

 private:
  void* context_ = nullptr;  // OSMesaContext, kept opaque so GL headers stay in the .cpp
  std::vector<unsigned char> buffer_;
  int width_;
  int height_;
  std::thread::id owner_;
};

}  // namespace gbdcs::sim::detail
