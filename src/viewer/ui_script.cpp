#include "viewer/ui_script.h"

#include <algorithm>
#include <cstdio>
#include <exception>

#include "core/file_write.h"
#include "core/image_io.h"
#include "core/memory.h"
#include "core/text.h"
#include "scene/save.h"
#include "viewer/save_dialog.h"
#include "viewer/navigation.h"
#include "viewer/scene_edit.h"
#include "viewer/ui_compare.h"

namespace kr::viewer {

ScriptRun::ScriptRun(const ViewOptions& options)
    : options_(options), latency_(options.measure_latency), idle_(options.measure_idle), start_(UiClock::now()) {}

bool ScriptRun::start(PanelContext& ctx) {
    // The --timeout clock started with this object, before the scene was loaded and the
    // window opened: whatever is slow there counts.
    if (!ctx.model.has_scene()) return true;
    // The command line's edits, in an interactive run too, go through the same functions as
    // the mouse and the panels.
    const bool ok = apply_script_edits(options_, ctx.model, [&](Edit kind, const auto& change) { return ctx.edit(kind, change); });
    if (!ok) return false;
    if (const auto& r = options_.region) ctx.ui.region = PixelBox{(*r)[0], (*r)[1], (*r)[2], (*r)[3]};
    if (options_.select) {
        // A click on the centre of the pixel, then a drag of the selection, as the mouse does.
        const Scene& s = ctx.model.scene();
        const CameraModel& camera = ctx.model.prepared()->camera;
        const int w = s.renderer.width, h = s.renderer.height;
        ctx.ui.selected = pick_primitive(s, camera, (options_.select->first + 0.5) / w, (options_.select->second + 0.5) / h);
        if (!ctx.ui.selected) {
            std::fprintf(stderr, "error: --select: no sphere at that pixel\n");
            return false;
        }
        std::printf("selected: %d\n", *ctx.ui.selected);
        if (options_.move_selection) {
            const int p = *ctx.ui.selected;
            const Vec3 from = s.shapes[size_t(s.primitives[size_t(p)].shape)].centre;
            const Vec3 to = from + drag_offset(camera, from, options_.move_selection->first,
                                               options_.move_selection->second, h, -1);
            ctx.edit(Edit::object, [&](Scene& sc, ViewerSettings&) { own_shape(sc, p).centre = to; });
        }
    }
    // A scripted run needs its image B; the window shows why it is missing.
    if (options_.scripted() && options_.reference && !ctx.ui.compare.comparison.reference()) {
        std::fprintf(stderr, "error: %s\n", ctx.messages.error.c_str());
        return false;
    }
    return true;
}

bool ScriptRun::step(PanelContext& ctx, const PixelRect& rect, const ReadBack& read, const std::function<void()>& submit) {
    if (script_timed_out(options_, start_, UiClock::now())) {
        status_ = 1;
        return true;
    }
    const ViewerModel& model = ctx.model;
    if (!model.has_scene()) {
        std::fprintf(stderr, "error: %s\n", ctx.messages.error.c_str());
        status_ = 1;
        return true;
    }
    const Snapshot* current = ctx.frame();
    if (latency_.running()) {
        if (const auto dx = latency_.on_frame(UiClock::now(), current != nullptr, current ? current->scale : 0)) {
            ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { orbit_drag(s.cameras[size_t(s.camera)], *dx, 0); });
            submit();  // at once, as handle_input's edits are submitted in the same frame
        }
        if (latency_.running()) return false;
        std::fputs(latency_.report().c_str(), stdout);
        std::fflush(stdout);
    }
    // Without an image to write, the latency run is over; an idle run ends in idle_step.
    if (!options_.writes_after_render()) return options_.measure_idle <= 0;
    // The screenshot waits for the render thread, never for time: N whole passes.
    const int needed = script_passes_needed(options_, model.settings());
    if (!(current && current->scale == 1 && current->spp >= needed)) return false;
    // A denoised image is saved from a frame with the halves (set_halves asks every frame for them).
    if (options_.save_image && save_waits_for_halves(image_save_kind(*options_.save_image), model, current))
        return false;
    const std::filesystem::path* writing = nullptr;  // the output being made, for its error
    try {
        if (options_.screenshot) {
            writing = &*options_.screenshot;
            // What is on screen of the image: all of it unless zoomed in.
            const PixelRect area = ctx.view_area();
            const double x0 = std::max(rect.x, area.x), y0 = std::max(rect.y, area.y);
            const double x1 = std::min(rect.x + rect.width, area.x + area.width);
            const double y1 = std::min(rect.y + rect.height, area.y + area.height);
            write_image(*options_.screenshot, read({x0, y0, x1 - x0, y1 - y0}));
            const double scale = rect.width / model.scene().renderer.width;
            std::printf("screenshot: %s (%d spp, generation %llu; image pixel %.6g,%.6g at %g screen pixels each, "
                        "at window pixel %.6g,%.6g)\n",
                        options_.screenshot->string().c_str(), current->spp,
                        static_cast<unsigned long long>(current->generation), (x0 - rect.x) / scale,
                        (y0 - rect.y) / scale, scale, x0, y0);
        }
        if (options_.stats_json) {
            writing = &*options_.stats_json;
            write_file_atomic(*options_.stats_json, stats_json(stats_figures(ctx)));
            std::printf("stats: %s\n", options_.stats_json->string().c_str());
        }
        if (options_.save_image) {
            // The Save panel's code, without its overwrite question.
            const std::filesystem::path& out = *options_.save_image;
            writing = &out;
            save_output(image_save_kind(out), out, ctx.model, current);
            std::printf("image: %s (%d spp)\n", out.string().c_str(), current->spp);
        }
        if (options_.save_scene) {
            writing = &*options_.save_scene;
            save_scene_json(model.scene_for_saving(), *options_.save_scene);
            std::printf("scene: %s\n", options_.save_scene->string().c_str());
        }
    } catch (const std::exception& e) {
        if (is_out_of_memory(e) && writing)
            std::fprintf(stderr, "error: %s: not enough memory to write it\n", show_user_text(writing->string()).c_str());
        else
            std::fprintf(stderr, "error: %s\n", e.what());
        status_ = 1;
    }
    std::fflush(stdout);
    return true;
}

void ScriptRun::window_shot(const ReadBack& read, int fb_w, int fb_h) {
    if (!options_.window_shot) return;
    try {
        write_image(*options_.window_shot, read({0, 0, double(fb_w), double(fb_h)}));
    } catch (const std::exception& e) {
        if (is_out_of_memory(e))
            std::fprintf(stderr, "error: %s: not enough memory to write it\n",
                         show_user_text(options_.window_shot->string()).c_str());
        else
            std::fprintf(stderr, "error: %s\n", e.what());
        status_ = 1;
    }
}

bool ScriptRun::idle_step(PanelContext& ctx, const std::function<void()>& pause) {
    const auto now = UiClock::now();
    if (script_timed_out(options_, start_, now)) {
        status_ = 1;
        return true;
    }
    if (!ctx.model.has_scene()) return false;  // step reports the error
    const RunStatus status = run_status(ctx.frame(), ctx.model.settings(), false);
    const IdleMeasure::Step step = idle_.step(now, status.state == RunState::done);
    if (step == IdleMeasure::Step::pause) {
        ctx.edit(Edit::run_control, [](Scene&, ViewerSettings& s) {
            s.paused = true;
            s.unlimited = true;
        });
        pause();
    }
    return step == IdleMeasure::Step::finished;
}

}  // namespace kr::viewer
