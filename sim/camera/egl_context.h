#pragma once

namespace slamrig::sim {

/// An OpenGL context without a window or a GPU: EGL on Mesa's surfaceless platform
/// (EGL_MESA_platform_surfaceless), which renders on the CPU with llvmpipe when there is no GPU.
/// MuJoCo draws into its own offscreen framebuffer object, so no EGL surface is needed.
class EglContext {
 public:
  /// Creates the context; throws std::runtime_error naming the EGL call that failed (no
  /// libegl-mesa0, no Mesa driver) and the EGL error code.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Makes this context current on the calling thread.
  void MakeCurrent() const;

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
};

}  // namespace slamrig::sim
