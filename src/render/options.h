// The flags `keithray render` and `keithray view` share: the render settings and scene
// overrides both commands take. One table (name, value, range from core/limits.h, help
// text, what it sets), read by one function and applied by one, so that the two commands
// accept the same values, print the same help and refuse with the same message.
// Flags only one command takes stay in its own parser, through the helpers of core/args.h.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/args.h"
#include "render/denoise.h"
#include "render/settings.h"
#include "render/stop_rule.h"
#include "scene/scene.h"

namespace kr {

// The shared flags as given; unset ones leave the scene file's value.
struct RenderOptions {
    std::optional<int> spp, depth;
    std::optional<uint64_t> seed;
    std::optional<Integrator> integrator;
    std::optional<Estimator> estimator;
    std::optional<Allocation> allocation;
    std::optional<LightSampling> light_sampling;
    std::optional<ToneMap> tonemap;
    std::optional<double> exposure;  // EV stops
    std::optional<Denoise> denoise;  // the develop step's denoiser (render/denoise.h)
    // --time and --noise (0: off); the pass limit comes from --spp or the file.
    StopRule stop;
};

enum class FlagKind { integer, number, name };

// One shared flag. Integer and number flags read a value in [lo, hi] ((lo, hi] when lo_open);
// name flags one of their enum's EnumNames.
struct SharedFlag {
    std::string_view name;   // "--spp"
    std::string_view value;  // the value's placeholder in the help: "N"
    FlagKind kind;
    double lo = 0, hi = 0;
    bool lo_open = false;
    std::string (*names)() = nullptr;  // name flags: "a | b | c"
    // The help text; "%r" stands for the range or the names.
    std::string_view help;
    // Reads `text` (already checked against the range) into its member of `options`.
    void (*read)(const SharedFlag& flag, const std::string& text, RenderOptions& options) = nullptr;
    // Name flags: the value of the flag given alone (last, or before another flag or a scene
    // file); empty: the flag needs a value.
    std::string_view bare = {};

    // "1..16777216", "(0, 1000000]", "wrt | pt | pt-naive".
    std::string range_text() const;
};

std::span<const SharedFlag> shared_flags();

// When the cursor's argument is a shared flag: reads its value into `options` (a bad one
// throws UsageError naming the flag, its range and the text) and returns true.
bool read_shared_flag(ArgCursor& args, RenderOptions& options);

// The shared flags' lines of a --help text, in the table's order.
std::string shared_flags_help();

// One apply for both commands: the settings a render of `scene` starts from (its renderer
// block) with the flags over them; the flags' tone map, exposure and denoise mode go into
// the scene's display block.
RenderSettings apply_render_options(const RenderOptions& options, Scene& scene);

// `keithray render`'s stop rule: --time and --noise, with --spp (or the file's samples) as the
// pass limit; open-ended without --spp, the cap of kMaxOpenEndedPasses.
StopRule render_stop_rule(const RenderOptions& options, const RenderSettings& settings);

}  // namespace kr
