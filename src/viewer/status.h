// What the status bar and the window title say about the render, computed without GL
// from the newest snapshot and the settings, so the rules are unit-tested.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"
#include "viewer/model.h"
#include "viewer/render_worker.h"

namespace kr::viewer {

// moving: no frame of the current view yet, while the window shows an earlier view's as the
// camera moves (a drag, the keys).
enum class RunState { starting, moving, rendering, paused, done, error };
inline constexpr EnumNames<RunState, 6> run_state_names{{"starting", "moving", "rendering", "paused", "done", "error"}};

struct RunStatus {
    RunState state = RunState::starting;
    int spp = 0, target = 0;
    bool unlimited = false;
    bool preview = false;      // the newest frame is a low-resolution preview
    double progress = -1;      // 0..1 towards the first stop rule to be met; -1: no rule
    double eta = -1;           // seconds to it; -1: unknown
    double elapsed = 0;        // render seconds of this image
    double mrays_per_second = 0;
    double noise = -1;         // estimated relative RMS error; -1 before 2 spp
    std::string rule;          // "spp", "time" or "noise" (stop_reason_names): the rule progress is towards
};

// `frame`: the newest snapshot of the current generation (null before the first).
// `has_error`: a load or edit failure is being shown (the last good image stays).
// `earlier_view`: with no frame, one of an earlier view is on screen (the camera moves).
RunStatus run_status(const Snapshot* frame, const ViewerSettings& settings, bool has_error, bool earlier_view = false);

// While a render region is set, the spp, the stop rules and the noise estimate count the
// whole image; the status bar adds the region's own figures from a full-resolution frame:
// the mean samples per pixel of the box's pixels and their estimated relative error (as
// RenderState::relative_error, over those pixels only; -1 while one has under 2 samples).
// None for a preview or a box with no pixel in the image.
struct RegionStatus {
    double samples_per_pixel = 0;
    double noise = -1;
};
std::optional<RegionStatus> region_status(const Snapshot& frame, const PixelBox& box);

// The status bar's first line is a row of fields, each of a width that holds its widest
// figure (so nothing moves as the figures change) and a priority (0: always shown). Where the
// window is too narrow for all, the fields of the largest priority number go first, so the
// state, the spp, the noise and the PSNR stay legible at any width; a less important field
// that still fits in what is left shows. Which fields show.
struct StatusField {
    double width = 0;
    int priority = 0;
};
std::vector<bool> fit_status_fields(const std::vector<StatusField>& fields, double available, double spacing);

// The noise estimate in the status bar, at most 9 characters: "5.61%", "0.0123%", "< 0.001%".
std::string format_noise(double noise);

// "assignment_03.json - 12/64 spp - rendering", with " (edited)" after the name when the
// scene has unsaved edits.
std::string window_title(std::string_view scene_name, const RunStatus& status, bool dirty);

// The image the display shows of `frame` under `view`: its radiance, its denoised radiance
// (where the worker made one), or the raw left half beside the denoised right half.
// A preview, given the image's full `width` and `height`, is upscaled to it smoothly
// (core/image.h upscale_linear): a coarse image, not blocks.
Image shown_radiance(const Snapshot& frame, DenoiseView view, int width = 0, int height = 0);
// The frame's own image where shown_radiance would be a copy of it (its radiance or its
// denoised radiance, at full resolution); null where the shown image is composed (split,
// upscaled): what the display uploads without a copy.
const Image* shown_image_in_place(const Snapshot& frame, DenoiseView view, int width = 0, int height = 0);
// The 8-bit picture the window shows of `frame` at 1:1 with the display's tone map.
Rgb8Image displayed_picture(const Snapshot& frame, DenoiseView view, int width, int height,
                            const DisplaySettings& display);
// The status bar's word for it: "raw", "denoised" or "split".
std::string_view shown_word(const Snapshot& frame, DenoiseView view);

// A number being typed into a panel field: keystrokes only change the held value; it is
// applied once, when the field is left (Enter or focus loss), so typing -20 never applies -2.
class TypedFields {
public:
    void hold(unsigned id, const double* values, int count) { held_[id].assign(values, values + count); }
    bool holding(unsigned id) const { return held_.count(id) != 0; }
    // The value to apply when field `id` is left, and forgets it.
    std::optional<std::vector<double>> take(unsigned id);

private:
    std::map<unsigned, std::vector<double>> held_;
};

}  // namespace kr::viewer
