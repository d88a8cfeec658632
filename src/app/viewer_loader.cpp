#include "app/viewer_module.h"
#include "core/module.h"

namespace kr {

const ViewerModule& viewer_module() {
    return *static_cast<const ViewerModule*>(
        load_module("viewer", nullptr, "the viewer", "libglfw3, libosmesa6 and libimgui"));
}

}  // namespace kr
