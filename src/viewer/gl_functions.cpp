#include "viewer/gl_functions.h"

#include <stdexcept>

namespace kr::viewer {

void GlFunctions::load(GetProc get_proc) {
    // Function pointer to function pointer: a well-defined cast back to the real type.
#define KR_GL_LOAD(name, type)                                                         \
    name = reinterpret_cast<type>(get_proc("gl" #name));                               \
    if (!name) throw std::runtime_error("the GL context does not provide gl" #name);
    KR_GL_FUNCTIONS(KR_GL_LOAD)
#undef KR_GL_LOAD
}

std::string GlFunctions::describe() const {
    auto text = [this](GLenum what) {
        const GLubyte* s = GetString(what);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    return text(GL_RENDERER) + " / OpenGL " + text(GL_VERSION);
}

}  // namespace kr::viewer
