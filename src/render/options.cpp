#include "render/options.h"

#include <array>

#include "core/limits.h"

namespace kr {

namespace {

// Readers: the value is parsed against the entry's own range, then stored in `Member`.
template <typename Value, auto Member>
void read_integer(const SharedFlag& f, const std::string& text, RenderOptions& o) {
    o.*Member = Value(parse_integer(std::string(f.name), text, (long long)f.lo, (long long)f.hi));
}

// `Path`: a member of RenderOptions, then members of it (--time is o.stop.seconds).
template <auto... Path>
void read_decimal(const SharedFlag& f, const std::string& text, RenderOptions& o) {
    (o .* ... .* Path) = parse_number(std::string(f.name), text, f.lo, f.hi, f.lo_open);
}

template <const auto& Names, auto Member>
void read_name(const SharedFlag& f, const std::string& text, RenderOptions& o) {
    o.*Member = parse_name(std::string(f.name), text, Names);
}

template <const auto& Names>
std::string name_choices() {
    std::string out;
    for (const std::string_view n : Names.names) out += (out.empty() ? "" : " | ") + std::string(n);
    return out;
}

template <typename Value, auto Member>
constexpr SharedFlag integer_flag(std::string_view name, std::string_view value, long long lo, long long hi,
                                  std::string_view help) {
    return {name, value, FlagKind::integer, double(lo), double(hi), false, nullptr, help, read_integer<Value, Member>};
}

template <auto... Path>
constexpr SharedFlag number_flag(std::string_view name, std::string_view value, double lo, double hi, bool lo_open,
                                 std::string_view help) {
    return {name, value, FlagKind::number, lo, hi, lo_open, nullptr, help, read_decimal<Path...>};
}

template <const auto& Names, auto Member>
constexpr SharedFlag name_flag(std::string_view name, std::string_view help, std::string_view bare = {}) {
    return {name, bare.empty() ? "NAME" : "[NAME]", FlagKind::name, 0, 0, false, name_choices<Names>, help,
            read_name<Names, Member>, bare};
}

using O = RenderOptions;

const std::array kFlags{
    integer_flag<int, &O::spp>("--spp", "N", 1, kMaxSamples,
                               "samples per pixel, %r (default: the file's \"samples\"; with --time or --noise, "
                               "an upper bound)"),
    number_flag<&O::stop, &StopRule::seconds>("--time", "SECONDS", 0, kMaxSeconds, true,
                                              "stop after SECONDS of rendering, in %r (checked between passes)"),
    number_flag<&O::stop, &StopRule::noise>("--noise", "X", kMinNoise, kMaxNoise, false,
                                            "stop when the estimated relative RMS error of the image falls below X, "
                                            "in %r (e.g. 0.01); adaptive: passes go to the noisiest pixels"),
    name_flag<integrator_names, &O::integrator>(
        "--integrator", "%r (default: the file's renderer type; pt-naive samples no area light, only point lights)"),
    name_flag<estimator_names, &O::estimator>(
        "--estimator", "where samples come from: %r (default: sobol, Owen-scrambled Sobol in every dimension; "
                       "stratified is the brief's sub-pixel strata; docs/accuracy.md)"),
    name_flag<allocation_names, &O::allocation>(
        "--allocation", "how a pass spreads its samples: %r (default: adaptive, each pixel's share in proportion to "
                        "its estimated noise after 8 passes, the same total; --spp N is then the mean per pixel; "
                        "stratified always gets uniform)"),
    name_flag<light_sampling_names, &O::light_sampling>(
        "--light-sampling", "spherical lights: %r (default: brief, the integral of the brief's reference images, "
                            "importance sampled; brief-area is the brief's own uniform sampling of it; cone and "
                            "area are exact: docs/fidelity.md, docs/accuracy.md)"),
    integer_flag<int, &O::depth>("--depth", "N", 0, kMaxDepth, "maximum ray depth, %r (default: the file's \"depth\")"),
    integer_flag<uint64_t, &O::seed>("--seed", "N", 0, kMaxSeed, "random seed, %r (default: 0); same seed, same image"),
    name_flag<tonemap_names, &O::tonemap>("--tonemap", "%r (default: the scene's \"display\" block, else sigmoid)"),
    number_flag<&O::exposure>("--exposure", "EV", -kMaxExposureStops, kMaxExposureStops, false,
                              "exposure in stops, in %r: radiance x 2^EV before the tone map (default: the "
                              "scene's \"display\" block, else 0)"),
    name_flag<denoise_names, &O::denoise>(
        "--denoise", "%r: denoise the image, guided by albedo, normal and depth: render and the viewer's Save run "
                     "non-local means over the two halves of the samples, the viewer's display the faster a-trous "
                     "filter (biased: compare --statistical tests raw images; an .exr keeps the raw radiance as "
                     "raw.R/G/B; docs/denoising.md); given alone (last, or before a flag or a .json): on (default: the "
                     "scene's \"display\" block, else off for render, on for view's display)",
        "on"),
};

// Help lines: the flag and its value in a 22-column field, the text wrapped at 90 columns.
void append_wrapped(std::string& out, std::string head, std::string_view text) {
    constexpr size_t kIndent = 24, kWidth = 90;
    if (head.size() + 1 < kIndent) head.resize(kIndent, ' ');
    else head += ' ';
    std::string line = head;
    size_t at = 0;
    bool first_word = true;
    while (at < text.size()) {
        size_t end = text.find(' ', at);
        if (end == std::string_view::npos) end = text.size();
        const std::string_view word = text.substr(at, end - at);
        if (!first_word && line.size() + 1 + word.size() > kWidth) {
            out += line + "\n";
            line = std::string(kIndent, ' ');
            first_word = true;
        }
        if (!first_word) line += ' ';
        line += word;
        first_word = false;
        at = end + 1;
    }
    out += line + "\n";
}

}  // namespace

std::string SharedFlag::range_text() const {
    if (kind == FlagKind::name) return names();
    if (kind == FlagKind::integer) return std::to_string((long long)lo) + ".." + std::to_string((long long)hi);
    std::string text(lo_open ? "(" : "[");
    text += bound_text(lo);
    text += ", ";
    text += bound_text(hi);
    text += "]";
    return text;
}

std::span<const SharedFlag> shared_flags() { return kFlags; }

bool read_shared_flag(ArgCursor& args, RenderOptions& options) {
    for (const SharedFlag& flag : kFlags)
        if (args.arg() == flag.name) {
            // A flag with a bare value stands alone before another flag or a scene file (.json).
            const char* peek = args.peek();
            const std::string next = peek ? peek : "";
            const bool alone = !peek || next.starts_with('-') || (next.size() > 5 && next.ends_with(".json"));
            flag.read(flag, flag.bare.empty() || !alone ? args.value() : std::string(flag.bare), options);
            return true;
        }
    return false;
}

std::string shared_flags_help() {
    std::string out;
    for (const SharedFlag& flag : kFlags) {
        std::string text(flag.help);
        if (const size_t r = text.find("%r"); r != std::string::npos) text.replace(r, 2, flag.range_text());
        append_wrapped(out, "  " + std::string(flag.name) + " " + std::string(flag.value), text);
    }
    return out;
}

RenderSettings apply_render_options(const RenderOptions& options, Scene& scene) {
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    if (options.spp) settings.target_spp = *options.spp;
    if (options.depth) settings.max_depth = *options.depth;
    if (options.seed) settings.seed = *options.seed;
    if (options.integrator) settings.integrator = *options.integrator;
    if (options.estimator) settings.estimator = *options.estimator;
    if (options.allocation) settings.allocation = *options.allocation;
    if (options.light_sampling) settings.light_sampling = *options.light_sampling;
    if (options.tonemap) scene.display.tonemap = *options.tonemap;
    if (options.exposure) scene.display.exposure = *options.exposure;
    if (options.denoise) scene.display.denoise = *options.denoise;
    return settings;
}

StopRule render_stop_rule(const RenderOptions& options, const RenderSettings& settings) {
    StopRule rule = options.stop;
    // Without --spp an open-ended render still ends: a noise target the scene cannot reach in
    // reasonable time stops at the cap (core/limits.h).
    rule.max_passes = rule.open_ended() && !options.spp ? kMaxOpenEndedPasses : settings.target_spp;
    return rule;
}

}  // namespace kr
