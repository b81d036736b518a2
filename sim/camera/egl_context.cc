#include "sim/camera/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace slamrig::sim {
namespace {

[[noreturn]] void Fail(const char* call) {
  char code[16];
  std::snprintf(code, sizeof(code), "0x%04x", static_cast<unsigned>(eglGetError()));
  throw std::runtime_error(std::string("EGL: ") + call + " failed (error " + code +
                           "); offscreen rendering needs Mesa's surfaceless EGL platform "
                           "(packages libegl-mesa0, libegl-dev, libgl1-mesa-dri)");
}

}  // namespace

EglContext::EglContext() {
  EGLDisplay display =
      eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) Fail("eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA)");
  EGLint major = 0, minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) Fail("eglInitialize");
  const EGLint attributes[] = {EGL_RED_SIZE,
                               8,
                               EGL_GREEN_SIZE,
                               8,
                               EGL_BLUE_SIZE,
                               8,
                               EGL_ALPHA_SIZE,
                               8,
                               EGL_DEPTH_SIZE,
                               24,
                               EGL_STENCIL_SIZE,
                               8,
                               EGL_COLOR_BUFFER_TYPE,
                               EGL_RGB_BUFFER,
                               EGL_SURFACE_TYPE,
                               EGL_PBUFFER_BIT,
                               EGL_RENDERABLE_TYPE,
                               EGL_OPENGL_BIT,
                               EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  if (eglChooseConfig(display, attributes, &config, 1, &num_configs) != EGL_TRUE ||
      num_configs < 1) {
    Fail("eglChooseConfig (RGBA8, depth 24, OpenGL)");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) Fail("eglBindAPI(EGL_OPENGL_API)");
  // MuJoCo 2.2 draws with the fixed-function pipeline: a compatibility context (the default).
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, nullptr);
  if (context == EGL_NO_CONTEXT) Fail("eglCreateContext");
  display_ = display;
  context_ = context;
  MakeCurrent();
}

EglContext::~EglContext() {
  // The display stays initialised: other contexts in the process may share it.
  if (eglGetCurrentContext() == context_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  eglDestroyContext(display_, context_);
}

void EglContext::MakeCurrent() const {
  if (eglGetCurrentContext() == context_) return;
  if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
    Fail("eglMakeCurrent");
  }
}

}  // namespace slamrig::sim
