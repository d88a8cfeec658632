// PanelContext: the edit path, the frame on screen, the layout, and opening a scene.
#include "viewer/ui_context.h"

#include <algorithm>

#include <imgui.h>

#include "scene/load.h"
#include "viewer/scene_edit.h"
#include "viewer/ui_compare.h"
#include "viewer/ui_file_dialog.h"

namespace kr::viewer {

bool PanelContext::edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change, std::string_view field,
                        std::string_view group) {
    std::string why;
    if (!model.edit(kind, change, &why, field, group)) {
        messages.show_error(why);
        return false;
    }
    if (edit_resets(kind)) messages.error.clear();
    return true;
}

const Snapshot* PanelContext::frame() const {
    return ui.shown && ui.shown->generation == model.generation() ? ui.shown.get() : nullptr;
}

bool PanelContext::shows_earlier_view() const {
    return ui.shown && ui.shown->generation != model.generation() && ui.shown->generation >= model.view_base_generation();
}

const Snapshot* PanelContext::full_frame() const {
    const Snapshot* f = frame();
    return f && f->scale == 1 ? f : nullptr;
}

double PanelContext::status_bar_height() const {
    const ImGuiStyle& style = ImGui::GetStyle();
    // Two lines: the render's figures, then the message line.
    return (2 * ImGui::GetFrameHeightWithSpacing() + 2 * style.WindowPadding.y) * ImGui::GetIO().DisplayFramebufferScale.y;
}

PixelRect PanelContext::view_area() const {
    const ImGuiIO& io = ImGui::GetIO();
    const double panel = ui.panel_visible ? shown_panel_width(ui.panel_width, io.DisplaySize.x) * io.DisplayFramebufferScale.x : 0.0;
    return {0, 0, std::max(1.0, ui.framebuffer_width - panel), std::max(1.0, ui.framebuffer_height - status_bar_height())};
}

PixelRect PanelContext::image_rect() const {
    if (!model.has_scene()) return {};
    // Fitted whole (whole screen pixels per image pixel when it fits), or zoomed and panned.
    return ui.compare.view.placement(view_area(), model.scene().renderer.width, model.scene().renderer.height);
}

std::optional<int> PanelContext::selection() const {
    if (!ui.selected || !model.has_scene() || *ui.selected < 0 || size_t(*ui.selected) >= model.scene().primitives.size())
        return std::nullopt;
    return ui.selected;
}

void duplicate_selection(PanelContext& ctx) {
    const auto sel = ctx.selection();
    if (!sel) return;
    ctx.model.seal_undo_step();
    int copy = -1;
    const CameraModel& cam = ctx.model.prepared()->camera;
    ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) {
        const double r = s.shapes[size_t(s.primitives[size_t(*sel)].shape)].radius;
        copy = duplicate_primitive(s, *sel, cam.right * (2.2 * r));  // beside it, as seen
    }, "duplicate");
    if (copy >= 0) ctx.ui.selected = copy;
}

void delete_selection(PanelContext& ctx) {
    const auto sel = ctx.selection();
    if (!sel) return;
    ctx.model.seal_undo_step();
    if (ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) { delete_primitive(s, *sel); }, "delete"))
        ctx.ui.selected.reset();
}

void add_sphere_at_target(PanelContext& ctx) {
    ctx.model.seal_undo_step();
    int added = -1;
    const Camera cam = ctx.model.camera();
    ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) {
        // At the target, or nearer on the line of sight where that is inside a sphere or a light.
        const SpherePlace at =
            free_sphere_place(s, cam.position, cam.target, std::max(1e-3, 0.05 * length(cam.target - cam.position)));
        added = add_sphere(s, at.centre, at.radius);
    }, "add sphere");
    if (added >= 0) ctx.ui.selected = added, ctx.ui.selected_light.reset();  // the new sphere is the selection
}

void open_scene_asking(PanelContext& ctx, const std::filesystem::path& file) {
    if (ctx.model.dirty()) {
        ctx.ui.files.pending_open = file;
        ctx.ui.files.ask_discard = true;
        return;
    }
    open_scene(ctx, file);
}

void open_scene(PanelContext& ctx, const std::filesystem::path& file, bool keep_view) {
    SceneFiles& files = ctx.ui.files;
    try {
        if (keep_view) ctx.model.load_keeping_view(file);
        else ctx.model.load(file);
        // The messages and the selection of the scene shown before belong to it.
        ctx.messages.clear();
        ctx.ui.selected.reset();
        ctx.ui.selected_light.reset();
        if (file != files.watch.file()) {
            files.watch.watch(file);
            note_recent_file(ctx, FilePurpose::open_scene, file);
            ctx.ui.save.read_only = scene_file_read_only(file, data_dir());
            ctx.ui.save.paths = SavePaths::for_scene(ctx.model.scene(), ctx.ui.save.read_only);
            if (ctx.ui.save.read_only)
                ctx.messages.show_status("a bundled scene, opened as it ships: Save asks where to save your copy");
            // The brief's reference follows the scene; one the user chose stays.
            CompareTool& tool = ctx.ui.compare;
            if (tool.reference_automatic || !tool.comparison.reference()) {
                tool.comparison.clear_reference();
                tool.reference_automatic = false;
                tool.picture_key.clear();
                if (const auto brief = brief_reference_for(file)) load_reference(ctx, *brief, true);
            }
        }
    } catch (const SceneError& e) {
        ctx.messages.show_error(e.what());  // the last good scene stays on screen
        if (!ctx.model.has_scene()) files.watch.watch(file);
    }
}

}  // namespace kr::viewer
