// Whether an image is developed denoised: the scene's display block (scene/scene.h), the
// `--denoise` flag of render and view, and the develop step (render/denoise.h) share it.
#pragma once

#include "core/enum_names.h"

namespace kr {

// off: the raw estimate; on: denoised (render and the viewer's Save: the final filter,
// denoise_nlmeans; the viewer's live display: the interactive one, denoise_atrous).
enum class Denoise { off, on };
inline constexpr EnumNames<Denoise, 2> denoise_names{{"off", "on"}};

}  // namespace kr
