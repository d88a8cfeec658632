// The GL entry points the viewer uses, loaded through the current context's
// getProcAddress (glfwGetProcAddress or OSMesaGetProcAddress) into a table.
// libGL (the window, via GLFW/GLX) and libOSMesa both export gl* symbols; a direct call
// binds to whichever library the linker saw first, so no viewer code calls gl* directly
// (docs/viewer.md has the measurement).
#pragma once

#include <string>

#include <GL/glcorearb.h>

namespace kr::viewer {

// X-macro: (name without the gl prefix, pointer type).
#define KR_GL_FUNCTIONS(X)                                   \
    X(GetString, PFNGLGETSTRINGPROC)                         \
    X(GetError, PFNGLGETERRORPROC)                           \
    X(Viewport, PFNGLVIEWPORTPROC)                           \
    X(ClearColor, PFNGLCLEARCOLORPROC)                       \
    X(Clear, PFNGLCLEARPROC)                                 \
    X(Enable, PFNGLENABLEPROC)                               \
    X(Disable, PFNGLDISABLEPROC)                             \
    X(Scissor, PFNGLSCISSORPROC)                             \
    X(Finish, PFNGLFINISHPROC)                               \
    X(PixelStorei, PFNGLPIXELSTOREIPROC)                     \
    X(ReadBuffer, PFNGLREADBUFFERPROC)                       \
    X(ReadPixels, PFNGLREADPIXELSPROC)                       \
    X(CreateShader, PFNGLCREATESHADERPROC)                   \
    X(ShaderSource, PFNGLSHADERSOURCEPROC)                   \
    X(CompileShader, PFNGLCOMPILESHADERPROC)                 \
    X(GetShaderiv, PFNGLGETSHADERIVPROC)                     \
    X(GetShaderInfoLog, PFNGLGETSHADERINFOLOGPROC)           \
    X(DeleteShader, PFNGLDELETESHADERPROC)                   \
    X(CreateProgram, PFNGLCREATEPROGRAMPROC)                 \
    X(AttachShader, PFNGLATTACHSHADERPROC)                   \
    X(LinkProgram, PFNGLLINKPROGRAMPROC)                     \
    X(GetProgramiv, PFNGLGETPROGRAMIVPROC)                   \
    X(GetProgramInfoLog, PFNGLGETPROGRAMINFOLOGPROC)         \
    X(DeleteProgram, PFNGLDELETEPROGRAMPROC)                 \
    X(UseProgram, PFNGLUSEPROGRAMPROC)                       \
    X(GetUniformLocation, PFNGLGETUNIFORMLOCATIONPROC)       \
    X(Uniform1i, PFNGLUNIFORM1IPROC)                         \
    X(Uniform1f, PFNGLUNIFORM1FPROC)                         \
    X(Uniform4f, PFNGLUNIFORM4FPROC)                         \
    X(GenVertexArrays, PFNGLGENVERTEXARRAYSPROC)             \
    X(BindVertexArray, PFNGLBINDVERTEXARRAYPROC)             \
    X(DeleteVertexArrays, PFNGLDELETEVERTEXARRAYSPROC)       \
    X(DrawArrays, PFNGLDRAWARRAYSPROC)                       \
    X(GenTextures, PFNGLGENTEXTURESPROC)                     \
    X(DeleteTextures, PFNGLDELETETEXTURESPROC)               \
    X(BindTexture, PFNGLBINDTEXTUREPROC)                     \
    X(ActiveTexture, PFNGLACTIVETEXTUREPROC)                 \
    X(TexImage2D, PFNGLTEXIMAGE2DPROC)                       \
    X(TexSubImage2D, PFNGLTEXSUBIMAGE2DPROC)                 \
    X(TexParameteri, PFNGLTEXPARAMETERIPROC)

struct GlFunctions {
#define KR_GL_DECLARE(name, type) type name = nullptr;
    KR_GL_FUNCTIONS(KR_GL_DECLARE)
#undef KR_GL_DECLARE

    // Fills the table with `get_proc` (a context must be current). Throws
    // std::runtime_error naming the first function the context does not provide.
    // The shape of glfwGetProcAddress and OSMesaGetProcAddress alike.
    using GenericProc = void (*)();
    using GetProc = GenericProc (*)(const char* name);
    void load(GetProc get_proc);

    // "GL_RENDERER / GL_VERSION" of the current context, for logs and docs.
    std::string describe() const;
};

}  // namespace kr::viewer
