#include "render/headless_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glew.h>

#include <cstdio>

namespace sylva::render {

static Diagnostic GlError(const std::string& what) {
  Diagnostic d;
  d.kind = ErrorKind::kRuntime;
  d.message = "headless OpenGL: " + what;
  return d;
}

Expected<std::unique_ptr<HeadlessContext>> HeadlessContext::Create() {
  auto getDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!getDisplay) return GlError("EGL has no eglGetPlatformDisplayEXT");
  EGLDisplay display = getDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor))
    return GlError("cannot open the EGL surfaceless display (is Mesa's libegl installed?)");
  if (!eglBindAPI(EGL_OPENGL_API)) return GlError("EGL cannot bind desktop OpenGL");
  const EGLint configAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                  EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  eglChooseConfig(display, configAttribs, &config, 1, &count);
  const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                   4,
                                   EGL_CONTEXT_MINOR_VERSION,
                                   5,
                                   EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                   EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                   EGL_NONE};
  EGLContext context =
      eglCreateContext(display, count ? config : nullptr, EGL_NO_CONTEXT, contextAttribs);
  if (context == EGL_NO_CONTEXT) {
    eglTerminate(display);
    return GlError("cannot create an OpenGL 4.5 core context");
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    eglDestroyContext(display, context);
    eglTerminate(display);
    return GlError("cannot make the context current without a surface");
  }
  glewExperimental = GL_TRUE;
  const GLenum glew = glewInit();
  if (glew != GLEW_OK && glew != GLEW_ERROR_NO_GLX_DISPLAY) {
    eglDestroyContext(display, context);
    eglTerminate(display);
    return GlError(std::string("glewInit failed: ") +
                   reinterpret_cast<const char*>(glewGetErrorString(glew)));
  }
  glGetError();  // GLEW may leave an error behind
  std::unique_ptr<HeadlessContext> c(new HeadlessContext());
  c->display_ = display;
  c->context_ = context;
  return c;
}

HeadlessContext::~HeadlessContext() {
  if (display_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_) eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
}

std::string HeadlessContext::Renderer() const {
  const GLubyte* r = glGetString(GL_RENDERER);
  return r ? reinterpret_cast<const char*>(r) : "unknown";
}

}  // namespace sylva::render
