// Headless Mesa llvmpipe contexts for the tests (test_mesa_bc, test_runtime_gl): surfaceless EGL
// (EGL_MESA_platform_surfaceless, no display needed), the software rasteriser forced whatever GPU
// the machine has. Header-only; the including test links OpenGL::OpenGL and OpenGL::EGL.
#pragma once

#define EGL_EGLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace zhc::test {

struct EglContext {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
};

// Creates and makes current a context of `api` (EGL_OPENGL_API or EGL_OPENGL_ES_API) with
// `renderable` (EGL_OPENGL_BIT, EGL_OPENGL_ES3_BIT) and context attributes `attributes` (nullptr:
// the defaults). Returns "" on success, else what failed.
inline std::string make_llvmpipe_context(EGLenum api, EGLint renderable, const EGLint* attributes, EglContext* out) {
    setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
    setenv("GALLIUM_DRIVER", "llvmpipe", 1);
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) return "eglGetPlatformDisplayEXT missing";
    out->display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (out->display == EGL_NO_DISPLAY || !eglInitialize(out->display, &major, &minor))
        return "no surfaceless EGL display (eglInitialize failed)";
    if (!eglBindAPI(api)) return "eglBindAPI failed";
    const EGLint cfg_attr[] = {EGL_RENDERABLE_TYPE, renderable, EGL_NONE};
    EGLConfig cfg = EGL_NO_CONFIG_KHR;
    EGLint n = 0;
    // The surfaceless platform may expose no configs; a context without one needs
    // EGL_KHR_no_config_context (nothing is rendered to a surface).
    if (!eglChooseConfig(out->display, cfg_attr, &cfg, 1, &n) || n < 1) {
        const char* ext = eglQueryString(out->display, EGL_EXTENSIONS);
        if (!ext || !std::strstr(ext, "EGL_KHR_no_config_context"))
            return "no EGL config for the API and no EGL_KHR_no_config_context";
        cfg = EGL_NO_CONFIG_KHR;
    }
    out->context = eglCreateContext(out->display, cfg, EGL_NO_CONTEXT, attributes);
    if (out->context == EGL_NO_CONTEXT || !eglMakeCurrent(out->display, EGL_NO_SURFACE, EGL_NO_SURFACE, out->context))
        return "cannot make a surfaceless context current";
    return "";
}

inline void destroy_context(EglContext* c) {
    if (c->display == EGL_NO_DISPLAY) return;
    eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (c->context != EGL_NO_CONTEXT) eglDestroyContext(c->display, c->context);
    eglTerminate(c->display);
    *c = EglContext{};
}

}  // namespace zhc::test
