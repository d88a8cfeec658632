#include "render/checkpoint.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/hash.h"
#include "core/limits.h"
#include "core/text.h"
#include "render/trace.h"
#include "scene/save.h"

namespace kr {

namespace {

constexpr std::string_view kMagic = "keithray checkpoint\n";
static_assert(sizeof(Color) == 3 * sizeof(double), "checkpoints store Color as three doubles");

// A name as one word of the key ("x86-64-v3 float lanes" -> "x86-64-v3-float-lanes").
std::string word(std::string_view name) {
    std::string w(name);
    for (char& c : w)
        if (c == ' ') c = '-';
    return w;
}

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

class Writer {
public:
    std::string bytes;
    template <class T>
    void put(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
    }
    template <class T>
    void put_all(const std::vector<T>& values) {
        bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    }
};

class Reader {
public:
    Reader(std::string_view bytes, std::string where) : bytes_(bytes), where_(std::move(where)) {}
    template <class T>
    T get() {
        T value;
        std::memcpy(&value, take(sizeof(T)), sizeof(T));
        return value;
    }
    template <class T>
    void get_all(std::vector<T>& values, size_t count) {
        const char* p = take(count * sizeof(T));
        values.resize(count);
        std::memcpy(values.data(), p, count * sizeof(T));
    }
    std::string_view text(size_t count) { return {take(count), count}; }
    size_t left() const { return bytes_.size() - at_; }

private:
    const char* take(size_t count) {
        if (count > left()) throw std::runtime_error(where_ + ": checkpoint truncated (the file ends early)");
        const char* p = bytes_.data() + at_;
        at_ += count;
        return p;
    }
    std::string_view bytes_;
    std::string where_;
    size_t at_ = 0;
};

// A key's setting in words, for a refusal: what it is (with the flag that sets it) and how
// its value reads. Unknown names (a key of another keithray) show as they are.
struct SettingWords {
    std::string_view name;  // as in the key
    const char* words;
};
constexpr SettingWords kSettingWords[] = {
    {"integrator", "the integrator (--integrator)"},
    {"estimator", "the estimator (--estimator)"},
    {"allocation", "the sample allocation (--allocation)"},
    {"light-sampling", "the light sampling (--light-sampling)"},
    {"depth", "the path depth (--depth)"},
    {"spp", "the target samples per pixel (--spp)"},
    {"rr-depth", "the Russian roulette depth"},
    {"seed", "the seed (--seed)"},
    {"kernels", "the SIMD kernels (--kernels)"},
    {"passes", "the pass limit (--spp)"},
    {"noise", "the noise rule's target (--noise)"},
    {"min-samples", "the noise rule's samples per pixel before it trusts a variance"},
    {"adapt-every", "the noise rule's passes between checks"},
};

// A value of setting `name` as a refusal shows it: the noise target 0 as "none", the pass
// cap of an open-ended render named as such.
std::string value_words(std::string_view name, std::string_view value) {
    if (name == "noise" && value == "0") return "none";
    if (name == "passes" && value == std::to_string(kMaxOpenEndedPasses))
        return std::string(value) + " (the cap of a --time or --noise render without --spp)";
    return show_user_text(value, 40);
}

// Every "name=value" word of `checkpoint` and `here` that differs, in words: "the seed
// (--seed): 0 in the checkpoint, 7 here; ...". The keys list their names in one order.
std::string differences(const std::string& checkpoint, const std::string& here) {
    std::istringstream a(checkpoint), b(here);
    std::string wa, wb, out;
    while (true) {
        const bool more_a = bool(a >> wa), more_b = bool(b >> wb);
        if (!more_a && !more_b) break;
        if (!more_a) wa.clear();
        if (!more_b) wb.clear();
        if (wa == wb) continue;
        const size_t ea = wa.find('='), eb = wb.find('=');
        const std::string_view name_a = std::string_view(wa).substr(0, ea), name_b = std::string_view(wb).substr(0, eb);
        if (!more_a || !more_b || ea == std::string::npos || eb == std::string::npos || name_a != name_b) {
            // Keys of another layout: the words themselves.
            out += (out.empty() ? "" : "; ") + (more_a ? quote_user_text(wa) : std::string("(none)")) +
                   " in the checkpoint, " + (more_b ? quote_user_text(wb) : std::string("(none)")) + " here";
            break;
        }
        std::string what = quote_user_text(name_a);
        for (const SettingWords& s : kSettingWords)
            if (s.name == name_a) what = s.words;
        out += (out.empty() ? "" : "; ") + what + ": " + value_words(name_a, std::string_view(wa).substr(ea + 1)) +
               " in the checkpoint, " + value_words(name_b, std::string_view(wb).substr(eb + 1)) + " here";
    }
    return out.empty() ? "settings differ" : out;
}

// The first pixel (row by row) whose numbers no render writes, as "pixel (x, y): what", or
// "" when every pixel holds: finite radiance sums, compensations, half sums and carried
// fractions; sums of squares and of depths that are not NaN and not negative (a square's
// sum may overflow to +inf, documented as an unknown variance); at most as many samples
// accumulated as drawn, and in a half as in the pixel; no more drawn than `passes` passes
// give (kMaxPassSamples each); no sums without samples; a mask of 0 and 1; carried fractions
// within what the allocation carries.
std::string first_bad_pixel(const RenderState& state) {
    const PixelBuffers& px = state.buffers();
    const SamplePlan& plan = state.plan;
    const int width = state.width, passes = state.passes;
    const size_t n = px.sample_count.size();
    auto finite = [](const Color& c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z); };
    auto not_negative = [](double v) { return v >= 0; };  // false for NaN
    auto colour = [](const Color& c) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "(%g, %g, %g)", c.x, c.y, c.z);
        return std::string(buf);
    };
    auto number_text = [](double v) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", v);
        return std::string(buf);
    };
    for (size_t i = 0; i < n; ++i) {
        std::string why;
        const uint32_t count = px.sample_count[i];
        const Color& sq = px.radiance_sq_sum[i];
        if (!finite(px.radiance_sum[i])) why = "its radiance sum " + colour(px.radiance_sum[i]) + " is not finite";
        else if (!finite(px.radiance_compensation[i]))
            why = "its radiance sum's compensation " + colour(px.radiance_compensation[i]) + " is not finite";
        else if (!not_negative(sq.x) || !not_negative(sq.y) || !not_negative(sq.z))
            why = "its sum of squared radiance " + colour(sq) + " is negative or NaN";
        else if (!not_negative(px.luminance_sq_sum[i]))
            why = "its sum of squared luminance " + number_text(px.luminance_sq_sum[i]) + " is negative or NaN";
        else if (!not_negative(px.depth_sum[i]))
            why = "its sum of depths " + number_text(px.depth_sum[i]) + " is negative or NaN";
        else if (count > px.sample_index[i])
            why = std::to_string(count) + " samples accumulated but " + std::to_string(px.sample_index[i]) + " drawn";
        else if (uint64_t(px.sample_index[i]) > uint64_t(passes) * kMaxPassSamples)
            why = std::to_string(px.sample_index[i]) + " samples drawn in " + std::to_string(passes) + " passes (at most " +
                  std::to_string(kMaxPassSamples) + " a pass)";
        else if (count == 0 && (px.radiance_sum[i] != Color() || px.radiance_compensation[i] != Color() ||
                                sq != Color() || px.luminance_sq_sum[i] != 0 || px.depth_sum[i] != 0))
            why = "sums without a sample";
        else if (!plan.active.empty() && plan.active[i] > 1)
            why = "its noise-rule mask is " + std::to_string(plan.active[i]) + ", not 0 or 1";
        else if (!plan.sample_credit.empty() &&
                 !(plan.sample_credit[i] >= 0 && plan.sample_credit[i] <= 4.0f * float(kMaxPassSamples)))
            why = "its carried fraction of a sample " + number_text(plan.sample_credit[i]) + " is outside [0, " +
                  std::to_string(4 * kMaxPassSamples) + "]";
        else if (!px.half_sum.empty() && !finite(px.half_sum[i]))
            why = "its half's radiance sum " + colour(px.half_sum[i]) + " is not finite";
        else if (!px.half_count.empty() && px.half_count[i] > count)
            why = "a half of " + std::to_string(px.half_count[i]) + " samples out of " + std::to_string(count);
        if (!why.empty())
            return "pixel (" + std::to_string(i % size_t(width)) + ", " + std::to_string(i / size_t(width)) + "): " + why;
    }
    return "";
}

}  // namespace

CheckpointKey checkpoint_key(const Scene& scene, const RenderScene& prepared, const RenderSettings& settings,
                             const StopRule& rule) {
    // Where the image goes and how it is tone mapped do not change a sample.
    Scene samples_only = scene;
    samples_only.renderer.output.clear();
    samples_only.display = DisplaySettings{};
    CheckpointKey key;
    key.scene = fnv1a(scene_to_json(samples_only));
    key.width = scene.renderer.width;
    key.height = scene.renderer.height;
    key.settings = "integrator=" + word(integrator_names.name(settings.integrator)) +
                   " estimator=" + word(estimator_names.name(settings.estimator)) +
                   " allocation=" + word(allocation_names.name(settings.allocation)) +
                   " light-sampling=" + word(light_sampling_names.name(settings.light_sampling)) +
                   " depth=" + std::to_string(settings.max_depth) + " spp=" + std::to_string(settings.target_spp) +
                   " rr-depth=" + std::to_string(settings.rr_depth) + " seed=" + std::to_string(settings.seed) +
                   // Single- and double-precision lanes round differently.
                   " kernels=" + word(lane_kernels_names.name(lane_kernels(prepared, settings))) +
                   // The passes it may take, the implicit cap of an open-ended render included.
                   " passes=" + std::to_string(rule.max_passes) +
                   " noise=" + number(rule.noise) + " min-samples=" + std::to_string(rule.min_samples) +
                   " adapt-every=" + std::to_string(rule.adapt_every);
    return key;
}

std::string read_checkpoint_file(const std::filesystem::path& file, const CheckpointKey& expected) {
    const std::string where = show_user_text(file.string());
    const uint64_t pixels = uint64_t(expected.width) * uint64_t(expected.height);
    // Header, key (bounded generously), sums and counts, the mask and the fractions, the
    // halves, checksum.
    const uint64_t largest = kMagic.size() + 1024 + expected.settings.size() +
                             pixels * (4 * sizeof(Color) + 2 * sizeof(double) + 3 * sizeof(uint32_t) + 1 + sizeof(float));
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        throw std::runtime_error(where + ": cannot read the checkpoint: " +
                                 (ec ? ec.message() : std::string("not a regular file")));
    const uintmax_t size = std::filesystem::file_size(file, ec);
    if (ec) throw std::runtime_error(where + ": cannot read the checkpoint: " + ec.message());
    if (size > largest)
        throw std::runtime_error(where + ": " + std::to_string(size) + " bytes, larger than a checkpoint of this " +
                                 std::to_string(expected.width) + "x" + std::to_string(expected.height) + " render");
    std::ifstream f(file, std::ios::binary);
    std::string bytes(size_t(size), '\0');
    if (!f.read(bytes.data(), std::streamsize(size))) throw std::runtime_error(where + ": cannot read the checkpoint");
    return bytes;
}

std::string encode_checkpoint(const CheckpointKey& key, const RenderState& state) {
    Writer w;
    w.bytes.append(kMagic);
    w.put(kCheckpointVersion);
    w.put(key.scene);
    w.put(uint32_t(key.settings.size()));
    w.bytes.append(key.settings);
    w.put(int32_t(state.width));
    w.put(int32_t(state.height));
    w.put(int32_t(state.passes));
    w.put(state.rays);
    w.put(state.nonfinite_samples);
    w.put_all(state.radiance_sum());
    w.put_all(state.radiance_compensation());
    w.put_all(state.depth_sum());
    w.put_all(state.luminance_sq_sum());
    w.put_all(state.radiance_sq_sum());
    w.put_all(state.sample_count());
    w.put_all(state.sample_index());
    w.put(uint8_t(!state.plan.active.empty()));
    w.put_all(state.plan.active);
    w.put(uint8_t(!state.plan.sample_credit.empty()));
    w.put_all(state.plan.sample_credit);
    // The final denoiser's two halves (a render with --denoise): resumed, it reads the same ones.
    w.put(uint8_t(state.tracks_halves()));
    if (state.tracks_halves()) {
        w.put_all(state.buffers().half_sum);
        w.put_all(state.buffers().half_count);
    }
    w.put(fnv1a(w.bytes));
    return std::move(w.bytes);
}

void decode_checkpoint(const std::string& bytes, const std::filesystem::path& file, const CheckpointKey& expected,
                       RenderState& state) {
    const std::string where = show_user_text(file.string());
    auto refuse = [&](const std::string& why) { throw std::runtime_error(where + ": " + why); };
    if (bytes.compare(0, kMagic.size(), kMagic) != 0) refuse("not a keithray checkpoint");
    if (bytes.size() < kMagic.size() + sizeof(uint64_t)) refuse("checkpoint truncated (the file ends early)");
    Reader r(std::string_view(bytes).substr(kMagic.size()), where);
    const auto version = r.get<uint32_t>();
    if (version != kCheckpointVersion)
        refuse("checkpoint format version " + std::to_string(version) + "; this keithray reads version " +
               std::to_string(kCheckpointVersion));
    // The checksum first: a damaged file is named as such, not as another scene.
    const std::string_view body(bytes.data(), bytes.size() - sizeof(uint64_t));
    uint64_t checksum;
    std::memcpy(&checksum, bytes.data() + body.size(), sizeof checksum);
    if (fnv1a(body) != checksum) refuse("checkpoint damaged or truncated (its checksum does not match)");
    const auto scene = r.get<uint64_t>();
    const std::string settings(r.text(r.get<uint32_t>()));
    const int width = r.get<int32_t>(), height = r.get<int32_t>();
    // The size first: it is part of the scene too, and the clearer thing to name.
    if (width != expected.width || height != expected.height)
        refuse("checkpoint of a " + std::to_string(width) + "x" + std::to_string(height) + " image; this render is " +
               std::to_string(expected.width) + "x" + std::to_string(expected.height));
    if (scene != expected.scene)
        refuse("checkpoint of another scene (the scene's content differs from the one rendered then)");
    if (settings != expected.settings) refuse("checkpoint of other settings: " + differences(settings, expected.settings));
    RenderState restored(width, height);
    const size_t n = restored.sample_count().size();
    PixelBuffers& px = restored.buffers();
    restored.passes = r.get<int32_t>();
    restored.rays = r.get<uint64_t>();
    restored.nonfinite_samples = r.get<uint64_t>();
    r.get_all(px.radiance_sum, n);
    r.get_all(px.radiance_compensation, n);
    r.get_all(px.depth_sum, n);
    r.get_all(px.luminance_sq_sum, n);
    r.get_all(px.radiance_sq_sum, n);
    r.get_all(px.sample_count, n);
    r.get_all(px.sample_index, n);
    if (r.get<uint8_t>()) r.get_all(restored.plan.active, n);
    if (r.get<uint8_t>()) r.get_all(restored.plan.sample_credit, n);
    if (r.get<uint8_t>()) {
        r.get_all(px.half_sum, n);
        r.get_all(px.half_count, n);
    }
    if (r.left() != sizeof(uint64_t) || restored.passes < 0) refuse("checkpoint damaged (unexpected layout)");
    // A valid checksum says the bytes are those written, not that a render wrote them: the
    // numbers must be ones a render holds, or they would reach every layer of the image.
    if (const std::string bad = first_bad_pixel(restored); !bad.empty())
        refuse("checkpoint holds numbers no render writes, nothing resumed: " + bad);
    state = std::move(restored);
}

}  // namespace kr
