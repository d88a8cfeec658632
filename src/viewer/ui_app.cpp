#include "viewer/ui_app.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "core/file_write.h"
#include "core/memory.h"
#include "core/text.h"
#include "render/outputs.h"
#include "scene/load.h"
#include "viewer/navigation.h"
#include "viewer/ui_compare.h"
#include "viewer/ui_file_dialog.h"
#include "viewer/ui_overlays.h"
#include "viewer/ui_panels.h"

namespace kr::viewer {

static_assert(KeyEventQueue::kRelease == GLFW_RELEASE && KeyEventQueue::kPress == GLFW_PRESS &&
              KeyEventQueue::kRepeat == GLFW_REPEAT && KeyEventQueue::kModCtrl == GLFW_MOD_CONTROL &&
              KeyEventQueue::kModAlt == GLFW_MOD_ALT && KeyEventQueue::kModSuper == GLFW_MOD_SUPER &&
              KeyEventQueue::kFirstNonText == GLFW_KEY_ESCAPE && KeyEventQueue::kFirstModifier == GLFW_KEY_LEFT_SHIFT &&
              KeyEventQueue::kLastModifier == GLFW_KEY_RIGHT_SUPER);

namespace {

constexpr double kFrameInterval = 1.0 / 60;  // UI frame cap where there is no vsync (Xvfb)
constexpr double kMinFrameInterval = 1.0 / 120;  // ... and when a new snapshot cuts the wait short
constexpr double kWatchInterval = 0.25;      // seconds between scene-file polls while idle
constexpr double kSignalInterval = 0.05;     // ... under MPI, between looks at a stop signal
constexpr int kSettleFrames = 3;             // frames drawn after input so ImGui's state settles
constexpr int kMinWindowWidth = 640, kMinWindowHeight = 400;

ViewerApp* app_of(GLFWwindow* w) { return static_cast<ViewerApp*>(glfwGetWindowUserPointer(w)); }

// Installed before ImGui's (which chain to them): any input wakes a redraw.
void install_input_callbacks(GLFWwindow* w) {
    glfwSetCursorPosCallback(w, [](GLFWwindow* win, double x, double y) { app_of(win)->note_cursor(x, y); });
    glfwSetMouseButtonCallback(w, [](GLFWwindow* win, int button, int action, int mods) { app_of(win)->note_button(button, action, mods); });
    glfwSetScrollCallback(w, [](GLFWwindow* win, double, double) { app_of(win)->note_wheel(); });
    glfwSetKeyCallback(w, [](GLFWwindow* win, int key, int, int action, int mods) { app_of(win)->note_key(key, action, mods); });
    glfwSetCharCallback(w, [](GLFWwindow* win, unsigned) { app_of(win)->note_input(); });
    glfwSetWindowFocusCallback(w, [](GLFWwindow* win, int) { app_of(win)->note_input(); });
    glfwSetCursorEnterCallback(w, [](GLFWwindow* win, int entered) { app_of(win)->note_enter(entered != 0); });
    glfwSetFramebufferSizeCallback(w, [](GLFWwindow* win, int, int) { app_of(win)->note_input(); });
    glfwSetWindowRefreshCallback(w, [](GLFWwindow* win) { app_of(win)->note_input(); });
    glfwSetWindowCloseCallback(w, [](GLFWwindow* win) { app_of(win)->on_close_request(); });
    glfwSetDropCallback(w, [](GLFWwindow* win, int count, const char** paths) { app_of(win)->note_drop(count, paths); });
    glfwSetWindowContentScaleCallback(w, [](GLFWwindow* win, float, float) { app_of(win)->note_input(); });
}

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

ViewerApp::ViewerApp(ViewOptions options, SharedPasses* ranks)
    : options_(std::move(options)), ranks_(ranks), script_(options_) {
    model_.set_overrides(options_.render);
    model_.edit(Edit::run_control, [&](Scene&, ViewerSettings& s) {
        s.unlimited = options_.unlimited;
        s.stop = options_.render.stop;
        s.denoise = options_.render.denoise.value_or(Denoise::on) == Denoise::on ? DenoiseView::on : DenoiseView::off;
    });
    try {
        model_.load(options_.scene);
    } catch (const SceneError& e) {
        messages_.error = e.what();
    }
    // The command line's pixels must lie in the image, checked before a window opens.
    if (model_.has_scene())
        if (const std::string problem = script_problem(options_, model_.scene().renderer.width, model_.scene().renderer.height);
            !problem.empty())
            throw std::runtime_error(problem + "; nothing opened or written");
    ui_.files.watch.watch(options_.scene);
    // A bundled scene (install tree or res/) is never saved over: Save asks where (ui_panel_save.cpp).
    ui_.save.read_only = scene_file_read_only(options_.scene, data_dir());
    if (model_.has_scene()) ui_.save.paths = SavePaths::for_scene(model_.scene(), ui_.save.read_only);
    if (model_.has_scene() && ui_.save.read_only)
        messages_.show_status("a bundled scene, opened as it ships: Save asks where to save your copy");
    // The recent files and the UI scale (never for a scripted run: its output must not depend
    // on the user's settings, nor write them); --ui-scale overrides the kept scale.
    load_viewer_settings(ctx_, !options_.scripted());
    if (options_.ui_scale) ui_.files.ui_scale = *options_.ui_scale;
    if (model_.has_scene() && !options_.scripted()) note_recent_file(ctx_, FilePurpose::open_scene, options_.scene);
    // --drop: as files dropped on the window, at the first frame.
    ui_.files.drops = options_.drop;
    CompareTool& tool = ui_.compare;
    tool.comparison.settings = options_.compare;
    tool.locked_probe = options_.probe;
    // The compare panel opens when the command line asked for a compare view or a probe.
    tool.open_panel = options_.compare.mode != ViewMode::render || options_.probe;
    if (options_.reference) load_reference(ctx_, *options_.reference, false);
    else if (const auto brief = brief_reference_for(options_.scene)) load_reference(ctx_, *brief, true);

    // A scripted run whose render cannot fit is refused before the window opens, with the
    // estimate the render thread applies to every job (render_worker.cpp): the GL driver
    // (Mesa's llvmpipe) ends the process with SIGSEGV where its own allocations fail
    // (compiling the display's shaders under ulimit -v), which no message could report.
    if (model_.has_scene() && options_.writes_after_render()) {
        const int rw = model_.scene().renderer.width, rh = model_.scene().renderer.height;
        if (const std::string shortfall = memory_shortfall(render_memory_bytes(rw, rh, false, true),
                                                           "the render of a " + std::to_string(rw) + "x" +
                                                               std::to_string(rh) + " image");
            !shortfall.empty())
            throw std::runtime_error(show_user_text(options_.scene.string()) + ": " + shortfall);
    }
    if (!glfwInit()) throw std::runtime_error("cannot initialise GLFW (is there a display? try render --gl)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    const int w = model_.has_scene() ? model_.scene().renderer.width : 512;
    const int h = model_.has_scene() ? model_.scene().renderer.height : 512;
    // Room for the image at 1:1 when it is not huge, the panels beside it, the status bar below.
    const int win_w = std::min(w, 1400) + int(ui_.panel_width), win_h = std::max(std::min(h, 1000) + 48, 720);
    window_ = glfwCreateWindow(win_w, win_h, "keithray", nullptr, nullptr);
    if (!window_) {
        glfwTerminate();
        throw std::runtime_error("cannot open a window with an OpenGL 3.3 core context");
    }
    glfwSetWindowSizeLimits(window_, kMinWindowWidth, kMinWindowHeight, GLFW_DONT_CARE, GLFW_DONT_CARE);
    glfwSetWindowUserPointer(window_, this);
    install_input_callbacks(window_);
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(1);
    gl_.load(&glfwGetProcAddress);
    std::fprintf(stderr, "keithray view: window GL: %s\n", gl_.describe().c_str());
    display_ = std::make_unique<Display>(gl_);

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini litter in the working directory
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    // Keys and text reach ImGui through the queue (key_queue.h), not as GLFW reports them:
    // a press and its release between two frames would otherwise never show as pressed.
    // ImGui's callbacks, called when the queue hands an event over, chain to note_key.
    glfwSetKeyCallback(window_, [](GLFWwindow* win, int key, int scancode, int action, int mods) {
        app_of(win)->queue_key({false, key, scancode, action, mods, 0});
    });
    glfwSetCharCallback(window_, [](GLFWwindow* win, unsigned c) { app_of(win)->queue_key({true, 0, 0, 0, 0, c}); });
    ImGui_ImplOpenGL3_Init("#version 330 core");

    worker_ = std::make_unique<RenderWorker>([] { glfwPostEmptyEvent(); }, ranks_);
}

ViewerApp::~ViewerApp() {
    worker_.reset();  // joins the render thread before anything it could read goes away
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    display_.reset();
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
}

void ViewerApp::poll_watch() {
    SceneFiles& files = ui_.files;
    if (!files.watch.changed()) return;
    input_seen_ = true;  // something to show either way
    // Never drop the user's edits silently: with unsaved edits, ask. A changed view alone
    // is kept over the file's changes without asking.
    const WatchAction action = model_.has_scene() ? model_.on_file_changed() : WatchAction::reload;
    if (action == WatchAction::ask) {
        files.pending_open = files.watch.file();
        files.ask_discard = true;
        return;
    }
    open_scene(ctx_, files.watch.file(), action == WatchAction::reload_keep_view);
    if (action == WatchAction::reload_keep_view) messages_.show_status("reloaded the file's changes; kept your view");
}

void ViewerApp::sync_worker() {
    if (!model_.has_scene()) return;
    const ViewerSettings& s = model_.settings();
    Submitted& sub = submitted_;
    if (s.paused != sub.paused) worker_->set_paused(sub.paused = s.paused);
    if ((s.denoise != DenoiseView::off) != sub.denoise) worker_->set_denoise(sub.denoise = s.denoise != DenoiseView::off);
    // The feature layers only while a view shows them: the default render path makes none.
    if (const bool f = is_feature_view(ui_.compare.comparison.settings.mode); f != sub.features)
        worker_->set_features(sub.features = f);
    // The halves only while a save of a denoised image waits for them (or a scripted run will
    // save one): the others' frames carry them once the render is finished or paused.
    if (const bool h = ui_.save.waiting.has_value() || options_.save_image.has_value(); h != sub.halves)
        worker_->set_halves(sub.halves = h);
    const StopRule rule = s.stop_rule();
    if (model_.generation() != sub.generation) {
        sub.generation = model_.generation();
        sub.stop = rule;
        RenderJob job{sub.generation, model_.prepared(), s.render, rule, nullptr};
        if (ranks_) job.source = std::make_shared<const Scene>(model_.scene());  // what the ranks prepare
        worker_->submit(std::move(job));
    }
    // A new rule (target, unlimited, time, noise) keeps the samples taken (the reset rule: run control).
    if (rule != sub.stop) worker_->set_stop_rule(sub.stop = rule);
    // A render region keeps the samples too: only its pixels refine from the next pass on.
    if (ui_.region != sub.region) worker_->set_region(sub.region = ui_.region);
}

bool ViewerApp::fetch_frame() {
    std::shared_ptr<const Snapshot> frame = worker_->latest();
    const DenoiseView view = model_.settings().denoise;
    if (!frame || (frame->serial == ui_.shown_serial && view == shown_view_)) return false;
    ui_.shown_serial = frame->serial;
    // A frame of an older generation shows an image the user already changed, except while
    // the user navigates: one of an earlier view of the same scene and settings (of the
    // image's size) keeps the picture following the hand until the current view's comes.
    if (frame->generation != model_.generation()) {
        const RendererSettings& image = model_.scene().renderer;
        const bool earlier_view = frame->generation >= model_.view_base_generation() &&
                                  frame->generation < model_.generation() && frame->error.empty() &&
                                  (frame->scale > 1 || (frame->radiance.width == image.width &&
                                                        frame->radiance.height == image.height)) &&
                                  (!ui_.shown || ui_.shown->generation <= frame->generation);
        if (!earlier_view) return false;
    }
    if (!frame->error.empty()) {  // the render could not go on (memory): the window says so
        messages_.show_error(frame->error);
        if (options_.scripted()) {  // its passes will never come
            std::fprintf(stderr, "error: %s: %s\n", options_.scene.string().c_str(), frame->error.c_str());
            failed_ = true;
            glfwSetWindowShouldClose(window_, GLFW_TRUE);
        }
        return false;
    }
    const RendererSettings& image = model_.scene().renderer;
    shown_view_ = view;
    if (const Image* in_place = shown_image_in_place(*frame, view, image.width, image.height))
        display_->upload(*in_place);  // no copy of the frame's image
    else
        display_->upload(shown_radiance(*frame, view, image.width, image.height));
    ui_.shown = std::move(frame);
    return true;
}

Rgb8Image ViewerApp::read_image_region(const PixelRect& rect) const {
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    const int x = int(rect.x), w = int(rect.width), h = int(rect.height);
    const int y = fb_h - int(rect.y) - h;  // GL rows count from the bottom
    std::vector<unsigned char> rgba(size_t(w) * h * 4);
    gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl_.ReadBuffer(GL_BACK);
    gl_.ReadPixels(x, y, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    Rgb8Image out{w, h, std::vector<uint8_t>(size_t(w) * h * 3)};
    for (int row = 0; row < h; ++row)
        for (int col = 0; col < w; ++col)
            for (int k = 0; k < 3; ++k)
                out.bytes[(size_t(row) * w + col) * 3 + k] = rgba[(size_t(h - 1 - row) * w + col) * 4 + k];
    return out;
}

void ViewerApp::end_with_the_job() {
    const std::string lost = ranks_->lost();
    const std::string message = "the MPI job is ending (" + (lost.empty() ? "a stop signal: a rank died, or mpirun was stopped" : lost) +
                                "): the session ends; unsaved edits are lost";
    messages_.show_error(message);
    std::fprintf(stderr, "error: %s\n", message.c_str());
    std::fflush(stderr);
    std::fflush(stdout);
    draw_frame();  // the message, in the window
    std::_Exit(1);
}

void ViewerApp::note_key(int key, int action, int mods) {
    input_seen_ = true;
    input_.note_key(key, action, mods);
}

void ViewerApp::note_drop(int count, const char** paths) {
    input_seen_ = true;
    for (int i = 0; i < count; ++i) ui_.files.drops.emplace_back(paths[i]);
}

void ViewerApp::apply_ui_scale() {
    float xs = 1, ys = 1;
    glfwGetWindowContentScale(window_, &xs, &ys);
    content_scale_ = xs > 0 ? xs : 1;
    const float scale = std::clamp(content_scale_ * float(ui_.files.ui_scale), 0.5f, 6.0f);
    if (scale == applied_scale_) return;
    // ImGui's own font (ProggyClean) rasterised at the size, at whole pixels; the style's sizes
    // (padding, spacing, rounding) from the default's; the panel keeps its share of the window.
    ImGuiIO& io = ImGui::GetIO();
    io.Fonts->Clear();
    ImFontConfig font;
    font.SizePixels = std::round(13.0f * scale);
    io.Fonts->AddFontDefault(&font);
    ImGui_ImplOpenGL3_DestroyFontsTexture();
    ImGui_ImplOpenGL3_CreateFontsTexture();
    ImGuiStyle style;
    ImGui::StyleColorsDark(&style);
    style.ScaleAllSizes(scale);
    ImGui::GetStyle() = style;
    ui_.panel_width *= scale / applied_scale_;
    applied_scale_ = scale;
}

void ViewerApp::request_quit() {
    if (model_.dirty()) quit_asked_ = true;
    else glfwSetWindowShouldClose(window_, GLFW_TRUE);
}

void ViewerApp::on_close_request() {
    // The window's close button: like Esc, it asks first when there are unsaved edits.
    if (model_.dirty() && !options_.scripted()) {
        glfwSetWindowShouldClose(window_, GLFW_FALSE);
        quit_asked_ = true;
    }
    input_seen_ = true;
}

void ViewerApp::toggle_fullscreen() {
    GLFWmonitor* monitor = glfwGetPrimaryMonitor();
    if (!fullscreen_) {
        const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr;
        if (!mode) return;
        glfwGetWindowPos(window_, &windowed_x_, &windowed_y_);
        glfwGetWindowSize(window_, &windowed_w_, &windowed_h_);
        glfwSetWindowMonitor(window_, monitor, 0, 0, mode->width, mode->height, mode->refreshRate);
        fullscreen_ = true;
    } else {
        glfwSetWindowMonitor(window_, nullptr, windowed_x_, windowed_y_, windowed_w_, windowed_h_, 0);
        fullscreen_ = false;
    }
}

bool ViewerApp::animating() const {
    if (input_.moving()) return true;
    if (messages_.flashing(UiClock::now())) return true;
    // The latency measurement redraws at the frame rate, as while dragging.
    return script_.measuring_latency();
}

void ViewerApp::update_title() {
    const RunStatus status = run_status(ctx_.frame(), model_.settings(), !messages_.error.empty() && !model_.has_scene(),
                                        ctx_.shows_earlier_view());
    const std::string name = ui_.files.watch.file().filename().string();
    std::string title = window_title(name, status, model_.dirty());
    if (title != title_) {
        glfwSetWindowTitle(window_, title.c_str());
        title_ = std::move(title);
    }
}

void ViewerApp::write_status_file(const RunStatus& status) {
    // press: the buttons down on the image as the last frame saw them (1 left, 2 right,
    // 4 middle, 8 the left one on the split view's divider); pointer: where
    // that frame saw the pointer (window points). Scripts wait on these before the next event.
    const ImGuiIO& io = ImGui::GetIO();
    // view, image (the image's corner in the framebuffer and its scale; "fit" when fitted),
    // probe (the locked pixel) and b (image B) follow the inspect and compare tools.
    const PixelRect rect = ctx_.image_rect();
    const CompareTool& tool = ui_.compare;
    char probe[48] = "none", b[32] = "none";
    if (tool.locked_probe) std::snprintf(probe, sizeof probe, "%d,%d", tool.locked_probe->first, tool.locked_probe->second);
    if (tool.comparison.b())
        std::snprintf(b, sizeof b, tool.comparison.settings.b < 0 ? "reference" : "slot%d", tool.comparison.settings.b + 1);
    // psnr: image A (as shown) against B, as the compare panel shows it ("none" without figures).
    char psnr[32] = "none";
    if (tool.figures) std::snprintf(psnr, sizeof psnr, "%.4f", tool.figures->psnr);
    // inside: the sphere the camera is in ("none"); fly: the navigation mode.
    std::string inside = ui_.inside_sphere ? *ui_.inside_sphere : "none";
    std::replace(inside.begin(), inside.end(), ' ', '_');
    // selected: the selected primitive's index in the scene block's list ("none").
    const auto sel = ctx_.selection();
    const std::string selected = sel ? std::to_string(*sel) : "none";
    // region: the render region's image pixels x0,y0,x1,y1 ("none": the whole image).
    char region[64] = "none";
    if (ui_.region) std::snprintf(region, sizeof region, "%d,%d,%d,%d", ui_.region->x0, ui_.region->y0, ui_.region->x1, ui_.region->y1);
    // draft: the region box being drawn (B, then a left drag), as region ("none").
    char draft[64] = "none";
    if (ui_.region_draft)
        std::snprintf(draft, sizeof draft, "%d,%d,%d,%d", ui_.region_draft->x0, ui_.region_draft->y0, ui_.region_draft->x1,
                      ui_.region_draft->y1);
    // feature: the feature view's readout of the pixel under the pointer, spaces as '_' ("none").
    std::string feature = tool.hover_feature.empty() ? "none" : tool.hover_feature.substr(0, 80);
    std::replace(feature.begin(), feature.end(), ' ', '_');
    // shown: the frame on screen, as generation,scale,spp,serial ("none" before the first).
    char shown[96] = "none";
    if (ui_.shown)
        std::snprintf(shown, sizeof shown, "%llu,%d,%d,%llu", static_cast<unsigned long long>(ui_.shown->generation),
                      ui_.shown->scale, ui_.shown->spp, static_cast<unsigned long long>(ui_.shown->serial));
    // grab: a move (M) is on; camera: the active camera's position (9 digits: a gesture's
    // result, compared between runs).
    char camera[96] = "none";
    if (model_.has_scene())
        std::snprintf(camera, sizeof camera, "%.9g,%.9g,%.9g", model_.camera().position.x, model_.camera().position.y,
                      model_.camera().position.z);
    // file: the scene file shown; exposure: the display's EV; ui_scale: the UI scale set and
    // content_scale the monitor's; dialog: a file dialog open (file_dialog_word), folder:
    // the browser's; error: an error message shows; recent: the recent scenes kept.
    auto spaceless = [](std::string s) {
        std::replace(s.begin(), s.end(), ' ', '_');
        return s.empty() ? std::string("none") : s.substr(0, 200);
    };
    const std::string file = spaceless(ui_.files.watch.file().filename().string());
    const std::string folder = spaceless(ui_.files.browser ? ui_.files.browser->folder().string() : "");
    char files_fields[600];
    std::snprintf(files_fields, sizeof files_fields,
                  " file=%s exposure=%.2f ui_scale=%.2f content_scale=%.2f dialog=%s folder=%s error=%d recent=%zu",
                  file.c_str(), model_.settings().tone.exposure, ui_.files.ui_scale, double(content_scale_),
                  file_dialog_word(ui_).c_str(), folder.c_str(), int(!messages_.error.empty()),
                  ui_.files.settings.scenes.size());
    char line[1000];
    int n = std::snprintf(line, sizeof line,
                  "state=%s spp=%d target=%d generation=%llu shown=%s dirty=%d help=%d panel=%d press=%d pointer=%d,%d "
                  "view=%s split=%.3f image=%g,%g,%s%g probe=%s b=%s psnr=%s bar=%s fly=%d inside=%s selected=%s primitives=%zu region=%s "
                  "feature=%s draft=%s question=%s grab=%d camera=%s\n",
                  std::string(run_state_names.name(status.state)).c_str(), status.spp, status.target,
                  static_cast<unsigned long long>(model_.generation()), shown, int(model_.dirty()), int(ui_.help_visible),
                  int(ui_.panel_visible), input_.pressed_bits(), int(std::lround(io.MousePos.x)),
                  int(std::lround(io.MousePos.y)), std::string(view_mode_names.name(tool.comparison.settings.mode)).c_str(),
                  tool.comparison.settings.split, rect.x, rect.y, tool.view.fitted() ? "fit" : "",
                  model_.has_scene() ? rect.width / model_.scene().renderer.width : 0.0, probe, b, psnr,
                  ui_.status_fields.empty() ? "none" : ui_.status_fields.c_str(), int(ui_.nav.fly),
                  inside.c_str(), selected.c_str(), model_.has_scene() ? model_.scene().primitives.size() : size_t(0), region,
                  feature.c_str(), draft, open_question(), int(input_.grab.has_value()), camera);
    // tab: the panel's tab; light: a light selected in the outliner ("none"); at: named
    // widgets' centres in window points, name:x,y;... (ui_widgets.h mark_item).
    std::string full(line, size_t(std::clamp(n, 0, int(sizeof line) - 1)));
    if (!full.empty() && full.back() == '\n') full.pop_back();
    full += files_fields;
    full += " tab=" + std::string(panel_tab_key(ui_.panel_tab)) + " light=" +
            (ui_.selected_light && !sel ? std::to_string(*ui_.selected_light) : std::string("none")) + " at=";
    for (const UiState::Mark& m : ui_.marks) {
        std::string name = m.name;
        std::replace(name.begin(), name.end(), ' ', '_');
        full += name + ":" + std::to_string(int(std::lround(m.x))) + "," + std::to_string(int(std::lround(m.y))) + ";";
    }
    full += "\n";
    if (full == status_line_ || status_file_failed_) return;
    try {
        write_file_atomic(*options_.status_file, full);
        status_line_ = full;
    } catch (const std::exception& e) {
        // Said once; a script waiting on the file would wait in vain, so a scripted run ends.
        std::fprintf(stderr, "error: --status-file: %s\n", e.what());
        failed_ = status_file_failed_ = true;
        if (options_.scripted()) glfwSetWindowShouldClose(window_, GLFW_TRUE);
    }
}

void ViewerApp::draw_panels() {
    ui_.marks.clear();
    if (!ui_.panel_visible) return;
    const ImGuiIO& io = ImGui::GetIO();
    const float bar_h = float(ctx_.status_bar_height() / std::max(1.0f, io.DisplayFramebufferScale.y));
    // The panel keeps the right edge above the status bar. The width the user chose stays
    // what it is: a small window only shows it narrower, and it comes back when the window grows.
    const float width = shown_panel_width(ui_.panel_width, float(io.DisplaySize.x));
    const float height = io.DisplaySize.y - bar_h;
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - width, 0));
    ImGui::SetNextWindowSize(ImVec2(width, height));
    ImGui::Begin("keithray", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoResize);
    // Labels keep their room: the fields narrow instead.
    ImGui::PushItemWidth(-std::min(kPanelLabelWidth * applied_scale_, 0.4f * width));
    draw_panel_list(ctx_);
    ImGui::PopItemWidth();
    ImGui::End();
    // The panel's left edge: a grip kPanelGripWidth wide that drags the width.
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - width - kPanelGripWidth / 2, 0));
    ImGui::SetNextWindowSize(ImVec2(kPanelGripWidth, height));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowMinSize, ImVec2(1, 1));
    ImGui::Begin("##panel edge", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoBackground | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoMove);
    ImGui::InvisibleButton("##grip", ImVec2(kPanelGripWidth, height));
    if (ImGui::IsItemHovered() || ImGui::IsItemActive()) ImGui::SetMouseCursor(ImGuiMouseCursor_ResizeEW);
    if (ImGui::IsItemActive())
        ui_.panel_width = shown_panel_width(io.DisplaySize.x - io.MousePos.x, io.DisplaySize.x);
    ImGui::End();
    ImGui::PopStyleVar(2);
}

// The questions (modal popups) are begun after every other window of the frame. ImGui 1.86
// asserts when a window appears after a modal in the modal's first frame (Esc then F1
// reaching one frame on a busy machine opened the quit question, then the help: an abort).
void ViewerApp::draw_questions(bool cancel, bool confirm) {
    const QuitAnswer answer = quit_popup(quit_asked_, cancel, confirm, ui_.save.read_only);
    if (answer == QuitAnswer::quit) glfwSetWindowShouldClose(window_, GLFW_TRUE);
    if (answer == QuitAnswer::save_and_quit) {
        save_scene_in_place(ctx_);  // a bundled scene's asks where: the quit waits for it
        quit_after_save_ = true;
    }
    // A key that answered the quit question answers nothing else (the save-where question it
    // opens waits for its own).
    const bool answered = answer != QuitAnswer::none;
    discard_popup(ctx_, cancel && !answered);
    overwrite_popup(ctx_, cancel && !answered, confirm && !answered);
    file_dialog_popup(ctx_, cancel && !answered, confirm && !answered);
    if (quit_after_save_) {
        // Saved: quit. Still asking (where, overwrite): wait. Else the save failed or was
        // cancelled (its message in the status bar): stay.
        const bool asking = ui_.save.ask_where || ui_.save.ask_overwrite || std::string_view(open_question()) != "none" ||
                            file_dialog_word(ui_) != "none";
        if (!model_.dirty()) glfwSetWindowShouldClose(window_, GLFW_TRUE);
        if (!model_.dirty() || !asking) quit_after_save_ = false;
    }
}

bool ViewerApp::draw_frame() {
    for (const KeyEvent& e : keys_.take_frame()) {
        if (e.text) ImGui_ImplGlfw_CharCallback(window_, e.codepoint);
        else ImGui_ImplGlfw_KeyCallback(window_, e.key, e.scancode, e.action, e.mods);
    }
    if (!keys_.empty()) input_seen_ = true;  // the rest go to the next frames, drawn at once
    apply_ui_scale();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    input_.apply_pointer();
    ImGui::NewFrame();
    input_.apply_button_positions();
    glfwGetFramebufferSize(window_, &ui_.framebuffer_width, &ui_.framebuffer_height);
    fetch_frame();
    finish_waiting_save(ctx_);
    if (model_.has_scene() && inside_checked_generation_ != model_.generation()) {
        inside_checked_generation_ = model_.generation();
        ui_.inside_sphere = sphere_containing(model_.scene(), model_.camera().position);
    }
    CompareTool& tool = ui_.compare;
    if (!tool.zoom_applied && model_.has_scene()) {
        tool.zoom_applied = true;  // --zoom, about the image's centre, once the layout is known
        const int w = model_.scene().renderer.width, h = model_.scene().renderer.height;
        if (options_.zoom > 0) tool.view.set_zoom(ctx_.view_area(), w, h, options_.zoom, w / 2.0, h / 2.0);
    }
    // The pictures of the frame just fetched, before the panels show their colour bars; again
    // below (a no-op unless the panels or the keys changed the view).
    update_pictures(ctx_, *display_);
    draw_panels();
    draw_status_bar(ctx_);
    draw_help(ui_);
    draw_error_flash(messages_);
    const WindowRequests requests = handle_input(ctx_, input_);
    if (requests.toggle_fullscreen) toggle_fullscreen();
    if (requests.quit) request_quit();
    handle_drops(ctx_);
    sync_worker();
    update_title();
    update_pictures(ctx_, *display_);

    const int fb_w = ui_.framebuffer_width, fb_h = ui_.framebuffer_height;
    gl_.Viewport(0, 0, fb_w, fb_h);
    gl_.ClearColor(0.1f, 0.1f, 0.1f, 1.0f);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
    const PixelRect rect = ctx_.image_rect();
    if (ui_.shown) draw_image(ctx_, *display_, rect, fb_w, fb_h);
    if (model_.has_scene()) draw_inspector(ctx_, rect);
    // After the inspector: the status line is the frame drawn, its pointer's readout included
    // (written before it, the readout of a frame that came while idle would stay a frame old).
    if (options_.status_file)
        write_status_file(run_status(ctx_.frame(), model_.settings(), !messages_.error.empty() && !model_.has_scene(),
                                     ctx_.shows_earlier_view()));
    // Scripted runs read the image region back here: what the shader drew, before
    // the panels are drawn over anything.
    const auto read = [this](const PixelRect& r) { return read_image_region(r); };
    const bool done = options_.scripted() && script_.step(ctx_, rect, read, [this] { sync_worker(); });
    draw_questions(requests.cancel_question, requests.confirm_question);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (done) script_.window_shot(read, fb_w, fb_h);
    glfwSwapBuffers(window_);
    return done;
}

int ViewerApp::run() {
    if (!script_.start(ctx_)) return 1;
    last_frame_ = UiClock::now();
    settle_frames_ = kSettleFrames;
    bool done = false;
    while (!done && !glfwWindowShouldClose(window_)) {
        if (ranks_ && (stop_signal() || !ranks_->lost().empty())) end_with_the_job();
        poll_watch();
        if (poll_file_chooser(ctx_)) input_seen_ = true;
        sync_worker();
        if (options_.measure_idle > 0 && script_.idle_step(ctx_, [this] {
                sync_worker();
                input_seen_ = true;  // draw the new state once
            }))
            break;
        // A message that expired goes from the status bar at once.
        messages_.error_sticks = !model_.has_scene();
        if (messages_.expire(UiClock::now())) input_seen_ = true;
        const auto latest = worker_->latest();
        const bool new_snapshot = latest && latest->serial != ui_.shown_serial;
        // Redraw only on input, a new snapshot, or something moving; else sleep until one of
        // those (the render thread and GLFW wake the wait) or the next poll of the scene file.
        if (!(input_seen_ || new_snapshot || settle_frames_ > 0 || animating())) {
            // Under MPI, a stop signal is seen within a fraction of mpirun's second before SIGKILL.
            glfwWaitEventsTimeout(ranks_ ? kSignalInterval : kWatchInterval);
            continue;
        }
        settle_frames_ = input_seen_ ? kSettleFrames : std::max(0, settle_frames_ - 1);
        input_seen_ = false;
        const auto frame_start = UiClock::now();
        done = draw_frame();
        if (done) break;

        const auto now = UiClock::now();
        const double work = seconds(now - frame_start);
        ui_.ui_work = ui_.ui_work > 0 ? 0.9 * ui_.ui_work + 0.1 * work : work;
        worker_->set_display_cost(ui_.ui_work);  // the frame schedule counts the window's drawing
        const double interval = seconds(now - last_frame_);
        last_frame_ = now;
        ui_.ui_fps = 0.9 * ui_.ui_fps + 0.1 * (interval > 0 ? 1.0 / interval : 0.0);
        if (ui_.shown && !ui_.shown->finished) script_.record_frame(work, interval);
        // Cap the UI rate where swap does not wait for vsync: the render thread needs the cores.
        // A new snapshot ends the wait early (the render thread posts an empty event).
        for (double left = kFrameInterval - seconds(UiClock::now() - frame_start); left > 0.001;
             left = kFrameInterval - seconds(UiClock::now() - frame_start)) {
            glfwWaitEventsTimeout(left);
            const auto newest = worker_->latest();
            if (newest && newest->serial != ui_.shown_serial && seconds(UiClock::now() - frame_start) >= kMinFrameInterval)
                break;
        }
        glfwPollEvents();
    }
    return failed_ ? 1 : script_.status();
}

}  // namespace kr::viewer
