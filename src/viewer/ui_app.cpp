#include "viewer/ui_app.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "core/file_write.h"
#include "core/image_io.h"
#include "render/trace.h"
#include "scene/load.h"
#include "scene/save.h"
#include "viewer/navigation.h"
#include "viewer/script.h"

namespace kr::viewer {

namespace {

constexpr double kFrameInterval = 1.0 / 60;  // UI frame cap where there is no vsync (Xvfb)
constexpr double kMinFrameInterval = 1.0 / 120;  // ... and when a new snapshot cuts the wait short
constexpr double kWatchInterval = 0.25;      // seconds between scene-file polls while idle
constexpr int kSettleFrames = 3;             // frames drawn after input so ImGui's state settles
constexpr double kErrorFlashSeconds = 3;     // a refused edit shows at the pointer this long
constexpr int kMinWindowWidth = 640, kMinWindowHeight = 400;

ViewerApp* app_of(GLFWwindow* w) { return static_cast<ViewerApp*>(glfwGetWindowUserPointer(w)); }

// Installed before ImGui's (which chain to them): any input wakes a redraw.
void install_input_callbacks(GLFWwindow* w) {
    glfwSetCursorPosCallback(w, [](GLFWwindow* win, double, double) { app_of(win)->note_input(); });
    glfwSetMouseButtonCallback(w, [](GLFWwindow* win, int, int, int) { app_of(win)->note_input(); });
    glfwSetScrollCallback(w, [](GLFWwindow* win, double, double) { app_of(win)->note_input(); });
    glfwSetKeyCallback(w, [](GLFWwindow* win, int key, int, int action, int) { app_of(win)->note_key(key, action); });
    glfwSetCharCallback(w, [](GLFWwindow* win, unsigned) { app_of(win)->note_input(); });
    glfwSetWindowFocusCallback(w, [](GLFWwindow* win, int) { app_of(win)->note_input(); });
    glfwSetCursorEnterCallback(w, [](GLFWwindow* win, int) { app_of(win)->note_input(); });
    glfwSetFramebufferSizeCallback(w, [](GLFWwindow* win, int, int) { app_of(win)->note_input(); });
    glfwSetWindowRefreshCallback(w, [](GLFWwindow* win) { app_of(win)->note_input(); });
    glfwSetWindowCloseCallback(w, [](GLFWwindow* win) { app_of(win)->on_close_request(); });
}

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

ViewerApp::ViewerApp(ViewOptions options)
    : options_(std::move(options)), latency_(options_.measure_latency), idle_(options_.measure_idle) {
    model_.set_overrides(options_.render);
    model_.edit(Edit::run_control, [&](Scene&, ViewerSettings& s) {
        s.unlimited = options_.unlimited;
        s.stop_seconds = options_.render.stop.seconds;
        s.stop_noise = options_.render.stop.noise;
    });
    try {
        model_.load(options_.scene);
    } catch (const SceneError& e) {
        error_ = e.what();
    }
    watch_.watch(options_.scene);
    reset_save_paths();
    compare_.settings = options_.compare;
    locked_probe_ = options_.probe;
    if (options_.reference) load_reference(*options_.reference, false);
    else if (const auto brief = brief_reference_for(options_.scene)) load_reference(*brief, true);

    if (!glfwInit()) throw std::runtime_error("cannot initialise GLFW (is there a display? try render --gl)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    const int w = model_.has_scene() ? model_.scene().renderer.width : 512;
    const int h = model_.has_scene() ? model_.scene().renderer.height : 512;
    // Room for the image at 1:1 when it is not huge, the panels beside it, the status bar below.
    const int win_w = std::min(w, 1400) + int(panel_width_), win_h = std::max(std::min(h, 1000) + 48, 720);
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
    ImGui_ImplOpenGL3_Init("#version 330 core");

    worker_ = std::make_unique<RenderWorker>([] { glfwPostEmptyEvent(); });
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

bool ViewerApp::edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change, std::string_view field,
                     std::string_view group) {
    std::string why;
    if (!model_.edit(kind, change, &why, field, group)) {
        show_error(why);
        return false;
    }
    if (edit_resets(kind)) {
        error_.clear();
        generation_edited_ = Clock::now();
    }
    return true;
}

void ViewerApp::show_error(std::string message) {
    error_ = std::move(message);
    error_time_ = Clock::now();
}

void ViewerApp::open_scene_asking(const std::filesystem::path& file) {
    if (model_.dirty()) {
        pending_open_ = file;
        open_pending_popup_ = true;
        return;
    }
    open_scene(file);
}

void ViewerApp::open_scene(const std::filesystem::path& file) {
    try {
        model_.load(file);
        error_.clear();
        generation_edited_ = Clock::now();
        if (file != watch_.file()) {
            watch_.watch(file);
            reset_save_paths();
            // The brief's reference follows the scene; one the user chose stays.
            if (reference_automatic_ || !compare_.reference()) {
                compare_.clear_reference();
                reference_automatic_ = false;
                picture_key_.clear();
                if (const auto brief = brief_reference_for(file)) load_reference(*brief, true);
            }
        }
    } catch (const SceneError& e) {
        show_error(e.what());  // the last good scene stays on screen
        if (!model_.has_scene()) watch_.watch(file);
    }
}

void ViewerApp::poll_watch() {
    if (!watch_.changed()) return;
    input_seen_ = true;  // something to show either way
    // Never drop the user's edits silently: with unsaved edits, ask.
    if (model_.has_scene() && model_.on_file_changed() == WatchAction::ask) {
        pending_open_ = watch_.file();
        open_pending_popup_ = true;
        return;
    }
    open_scene(watch_.file());
}

void ViewerApp::sync_worker() {
    if (!model_.has_scene()) return;
    const ViewerSettings& s = model_.settings();
    if (s.paused != submitted_paused_) worker_->set_paused(submitted_paused_ = s.paused);
    if (s.unlimited != submitted_unlimited_) worker_->set_unlimited(submitted_unlimited_ = s.unlimited);
    if (s.stop_seconds != submitted_stop_seconds_ || s.stop_noise != submitted_stop_noise_)
        worker_->set_stop_rule(submitted_stop_seconds_ = s.stop_seconds, submitted_stop_noise_ = s.stop_noise);
    if (model_.generation() != submitted_generation_) {
        submitted_generation_ = model_.generation();
        submitted_target_ = s.render.target_spp;
        worker_->submit({submitted_generation_, model_.prepared(), s.render});
    }
    // A new target keeps the samples taken (the reset rule: run control).
    if (s.render.target_spp != submitted_target_) worker_->set_target_spp(submitted_target_ = s.render.target_spp);
}

bool ViewerApp::fetch_frame() {
    std::shared_ptr<const Snapshot> frame = worker_->latest();
    if (!frame || frame->serial == shown_serial_) return false;
    shown_serial_ = frame->serial;
    // A frame of an older generation shows an image the user already changed.
    if (frame->generation != model_.generation()) return false;
    display_->upload(frame->radiance);
    shown_ = std::move(frame);
    return true;
}

double ViewerApp::status_bar_height() const {
    const ImGuiStyle& style = ImGui::GetStyle();
    // Two lines: the render's figures, then the message line.
    return (2 * ImGui::GetFrameHeightWithSpacing() + 2 * style.WindowPadding.y) * ImGui::GetIO().DisplayFramebufferScale.y;
}

PixelRect ViewerApp::view_area() const {
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    const double panel = panel_visible_ ? panel_width_ * ImGui::GetIO().DisplayFramebufferScale.x : 0.0;
    return {0, 0, std::max(1.0, fb_w - panel), std::max(1.0, fb_h - status_bar_height())};
}

PixelRect ViewerApp::image_rect() const {
    if (!model_.has_scene()) return {};
    // Fitted whole (whole screen pixels per image pixel when it fits), or zoomed and panned.
    return view_.placement(view_area(), model_.scene().renderer.width, model_.scene().renderer.height);
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

void ViewerApp::note_key(int key, int action) {
    input_seen_ = true;
    if (action == GLFW_PRESS && key_presses_.size() < 64) key_presses_.push_back(key);
}

void ViewerApp::handle_input() {
    if (!model_.has_scene()) {
        key_presses_.clear();
        return;
    }
    handle_mouse(image_rect());
    handle_keys();
    key_presses_.clear();
    // One drag, one held key or one field's edit is one undo step: seal it once nothing is held.
    const ImGuiIO& io = ImGui::GetIO();
    const bool holding = io.MouseDown[0] || io.MouseDown[1] || io.MouseDown[2] || ImGui::IsAnyItemActive() ||
                         motion_keys_held_;
    if (!holding) model_.seal_undo_step();
}

void ViewerApp::handle_mouse(const PixelRect& rect) {
    ImGuiIO& io = ImGui::GetIO();
    const double to_fb = io.DisplayFramebufferScale.x;  // window points to framebuffer pixels
    const int w = model_.scene().renderer.width, h = model_.scene().renderer.height;
    const double image_scale = rect.width / w;
    const double mx = io.MousePos.x * to_fb, my = io.MousePos.y * to_fb;
    const PixelRect area = view_area();
    auto inside = [&](const PixelRect& r) { return mx >= r.x && my >= r.y && mx < r.x + r.width && my < r.y + r.height; };
    const bool over_image = inside(area) && inside(rect);
    for (int b = 0; b < 3; ++b)
        if (!io.MouseDown[b]) drags_[b].release();
    if (!io.MouseDown[0]) divider_drag_ = false;
    // Mouse: only when ImGui does not want it, so a click on a panel never moves the camera.
    if (io.WantCaptureMouse || !over_image) {
        for (int b = 0; b < 3; ++b)
            if (ImGui::IsMouseClicked(b)) drags_[b].release();  // a press on a panel drags nothing
        if (!io.WantCaptureMouse && inside(area) && io.KeyCtrl && io.MouseWheel != 0)
            view_.zoom_steps(area, w, h, io.MouseWheel > 0 ? 1 : -1, mx, my);
    } else {
        for (int b = 0; b < 3; ++b)
            if (ImGui::IsMouseClicked(b))
                drags_[b].press(io.MouseClickedPos[b].x * to_fb, io.MouseClickedPos[b].y * to_fb);
        const bool left_click = ImGui::IsMouseClicked(ImGuiMouseButton_Left);
        const double divider_x = rect.x + compare_.settings.split * rect.width;
        if (left_click && io.KeyShift) {
            drags_[0].release();  // Shift+click locks the inspector on a pixel, or frees it
            const std::pair<int, int> pixel{int(std::floor((mx - rect.x) / image_scale)),
                                            int(std::floor((my - rect.y) / image_scale))};
            if (locked_probe_ == pixel) locked_probe_.reset();
            else locked_probe_ = pixel;
        } else if (left_click && compare_.settings.mode == ViewMode::split && std::abs(mx - divider_x) <= 6 * to_fb) {
            drags_[0].release();  // the split view's divider, never an orbit
            divider_drag_ = true;
        } else if (left_click && (io.KeyCtrl || pick_focus_)) {
            drags_[0].release();  // a focus click, never an orbit
            const Vec2 film = raster_to_camera((mx - rect.x) / rect.width * w, (my - rect.y) / rect.height * h, w, h);
            if (!model_.focus_at(film.x, film.y)) show_error("click-to-focus: nothing there to focus on");
            else generation_edited_ = Clock::now();
            pick_focus_ = false;
        }
        if (ImGui::IsMouseClicked(ImGuiMouseButton_Middle)) {
            // The middle button pans a zoomed image; on a fitted one it dollies the camera.
            middle_pans_ = !view_.fitted();
            pan_last_x_ = pan_last_y_ = 0;
        }
        if (io.MouseWheel != 0) {
            if (io.KeyCtrl) view_.zoom_steps(area, w, h, io.MouseWheel > 0 ? 1 : -1, mx, my);
            else
                edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
                    dolly(s.cameras[size_t(s.camera)], std::pow(0.9, double(io.MouseWheel)));
                }, "dolly", "wheel");
        }
    }
    if (divider_drag_) compare_.settings.split = std::clamp((mx - rect.x) / rect.width, 0.0, 1.0);
    // Drags started on the image go on wherever the pointer goes. Each applies its whole
    // offset from where it started (screen pixels, in image pixels here) to the camera as it was then.
    double dx = 0, dy = 0;
    const int active = model_.scene().camera;
    auto drag = [&](DragGesture& g) {
        if (!g.move(mx, my, model_.camera(), dx, dy)) return false;
        dx /= image_scale;
        dy /= image_scale;
        return true;
    };
    if (drag(drags_[0]))
        edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera cam = drags_[0].start_camera;
            orbit_drag(cam, dx, dy);
            s.cameras[size_t(active)] = cam;
        }, "orbit", "orbit");
    if (drag(drags_[1]))
        edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera cam = drags_[1].start_camera;
            pan_drag(cam, dx, dy, h);
            s.cameras[size_t(active)] = cam;
        }, "pan", "pan");
    if (middle_pans_) {
        // The image follows the pointer from where the button went down: this frame's part of
        // the drag, in screen pixels, once past the click threshold.
        if (drag(drags_[2])) {
            const double tx = mx - drags_[2].press_x, ty = my - drags_[2].press_y;
            view_.pan(area, w, h, tx - pan_last_x_, ty - pan_last_y_);
            pan_last_x_ = tx;
            pan_last_y_ = ty;
        }
    } else if (drag(drags_[2])) {
        edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera cam = drags_[2].start_camera;
            dolly(cam, std::exp(dy * 0.005));
            s.cameras[size_t(active)] = cam;
        }, "dolly", "dolly");
    }
}

bool ViewerApp::zoom_keys() {
    const int w = model_.scene().renderer.width, h = model_.scene().renderer.height;
    const PixelRect area = view_area();
    const ImGuiIO& io = ImGui::GetIO();
    // About the pointer when it is over the view, else about the view's centre.
    const double to_fb = io.DisplayFramebufferScale.x;
    double px = io.MousePos.x * to_fb, py = io.MousePos.y * to_fb;
    if (!(px >= area.x && py >= area.y && px < area.x + area.width && py < area.y + area.height)) {
        px = area.x + area.width / 2;
        py = area.y + area.height / 2;
    }
    bool acted = false;
    for (const int key : key_presses_) {
        acted = true;
        if (key == GLFW_KEY_EQUAL || key == GLFW_KEY_KP_ADD) view_.zoom_steps(area, w, h, 1, px, py);
        else if (key == GLFW_KEY_MINUS || key == GLFW_KEY_KP_SUBTRACT) view_.zoom_steps(area, w, h, -1, px, py);
        else if (key == GLFW_KEY_0 || key == GLFW_KEY_KP_0) view_.fit();
        else if (key == GLFW_KEY_1 || key == GLFW_KEY_KP_1) view_.one_to_one(area, w, h);
        else if (key == GLFW_KEY_V) {
            auto& mode = compare_.settings.mode;
            mode = ViewMode((int(mode) + 1) % int(view_mode_names.names.size()));
        } else if (key == GLFW_KEY_K && shown_ && shown_->scale == 1) {
            compare_.settings.b = compare_.keep(shown_->radiance, shown_->spp);
            picture_key_.clear();
            status_ = "kept the image as " + compare_.slots()[size_t(compare_.settings.b)]->name + " (image B)";
        } else acted = false;
    }
    return acted;
}

void ViewerApp::handle_keys() {
    ImGuiIO& io = ImGui::GetIO();
    const auto now = Clock::now();
    // A press this frame, whether ImGui saw the key down or it was released before the frame.
    auto pressed = [&](int key) {
        return ImGui::IsKeyPressed(key, false) ||
               std::find(key_presses_.begin(), key_presses_.end(), key) != key_presses_.end();
    };
    // The window keys, in the order they were pressed: taps that reach one frame together
    // (a busy machine) act as they would one frame each (F1 then Esc shows and closes the
    // help; Esc then F1 asks to quit, then shows the help). F1 and F11 work even while a
    // field has the keyboard.
    const bool typing = io.WantTextInput || ImGui::IsAnyItemActive();
    for (const int key : key_presses_) {
        if (key == GLFW_KEY_F11) toggle_fullscreen();
        else if (key == GLFW_KEY_F1) help_visible_ = !help_visible_;
        else if (typing) continue;
        else if (key == GLFW_KEY_ESCAPE) {
            if (help_visible_) help_visible_ = false;
            else if (!ImGui::IsPopupOpen(nullptr, ImGuiPopupFlags_AnyPopupId)) request_quit();
        } else if (key == GLFW_KEY_TAB) {
            panel_visible_ = !panel_visible_;
        }
    }
    if (typing) {
        motion_keys_held_ = false;
        return;
    }
    bool question = false;
    for (ImWchar c : io.InputQueueCharacters) question |= c == '?';
    if (question) help_visible_ = !help_visible_;
    if (io.KeyCtrl && (pressed(GLFW_KEY_Z) || pressed(GLFW_KEY_Y))) {
        const bool redo = pressed(GLFW_KEY_Y) || io.KeyShift;
        if (redo ? model_.redo() : model_.undo()) {
            error_.clear();
            generation_edited_ = Clock::now();
        }
        return;
    }
    if (pressed(GLFW_KEY_HOME) || pressed(GLFW_KEY_R)) {
        model_.seal_undo_step();
        if (model_.reset_view()) generation_edited_ = Clock::now();
    }
    if (pressed(GLFW_KEY_RIGHT_BRACKET) || pressed(GLFW_KEY_LEFT_BRACKET)) {
        const int spp = model_.settings().render.target_spp;
        model_.seal_undo_step();
        model_.set_target_spp(pressed(GLFW_KEY_RIGHT_BRACKET) ? std::min(spp * 2, 1 << 24) : std::max(1, spp / 2));
    }
    if (pressed(GLFW_KEY_F)) pick_focus_ = !pick_focus_;
    if (!io.KeyCtrl) zoom_keys();
    if (pressed(GLFW_KEY_SPACE))
        edit(Edit::run_control, [](Scene&, ViewerSettings& s) { s.paused = !s.paused; });
    if (io.KeyCtrl) {
        motion_keys_held_ = false;
        return;
    }
    // Held keys move the camera at rates per second: arrows orbit, W/S dolly, A/D/Q/E pan.
    KeyMotion keys;
    keys.orbit_x = int(ImGui::IsKeyDown(GLFW_KEY_RIGHT)) - int(ImGui::IsKeyDown(GLFW_KEY_LEFT));
    keys.orbit_y = int(ImGui::IsKeyDown(GLFW_KEY_DOWN)) - int(ImGui::IsKeyDown(GLFW_KEY_UP));
    keys.pan_x = int(ImGui::IsKeyDown(GLFW_KEY_A)) - int(ImGui::IsKeyDown(GLFW_KEY_D));
    keys.pan_y = int(ImGui::IsKeyDown(GLFW_KEY_E)) - int(ImGui::IsKeyDown(GLFW_KEY_Q));
    keys.dolly = int(ImGui::IsKeyDown(GLFW_KEY_S)) - int(ImGui::IsKeyDown(GLFW_KEY_W));
    if (keys.any()) {
        // The time since the previous frame with keys held; a first frame moves one 60 Hz step.
        const double dt = motion_keys_held_ ? std::clamp(seconds(now - last_motion_), 0.0, 0.1) : 1.0 / 60;
        const int h = model_.scene().renderer.height;
        edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            apply_key_motion(s.cameras[size_t(s.camera)], keys, dt, h);
        }, "camera keys", "keys");
    }
    motion_keys_held_ = keys.any();
    last_motion_ = now;
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
    const ImGuiIO& io = ImGui::GetIO();
    if (io.MouseDown[0] || io.MouseDown[1] || io.MouseDown[2] || motion_keys_held_) return true;
    if (!error_.empty() && seconds(Clock::now() - error_time_) < kErrorFlashSeconds) return true;
    // The latency measurement redraws at the frame rate, as while dragging.
    return latency_.running();
}

void ViewerApp::update_title() {
    const RunStatus status = run_status(shown_ && shown_->generation == model_.generation() ? shown_.get() : nullptr,
                                        model_.settings(), !error_.empty() && !model_.has_scene());
    const std::string name = watch_.file().filename().string();
    std::string title = window_title(name, status, model_.dirty());
    if (title != title_) {
        glfwSetWindowTitle(window_, title.c_str());
        title_ = std::move(title);
    }
    if (options_.status_file) write_status_file(status);
}

void ViewerApp::write_status_file(const RunStatus& status) {
    // press: the buttons down on the image as the last frame saw them (1 left, 2 right,
    // 4 middle, 8 the left one on the split view's divider); pointer: where
    // that frame saw the pointer (window points). Scripts wait on these before the next event.
    const ImGuiIO& io = ImGui::GetIO();
    // view, image (the image's corner in the framebuffer and its scale; "fit" when fitted),
    // probe (the locked pixel) and b (image B) follow the inspect and compare tools.
    const PixelRect rect = image_rect();
    char probe[48] = "none", b[32] = "none";
    if (locked_probe_) std::snprintf(probe, sizeof probe, "%d,%d", locked_probe_->first, locked_probe_->second);
    if (compare_.b()) std::snprintf(b, sizeof b, compare_.settings.b < 0 ? "reference" : "slot%d", compare_.settings.b + 1);
    char line[420];
    std::snprintf(line, sizeof line,
                  "state=%s spp=%d target=%d generation=%llu dirty=%d help=%d panel=%d press=%d pointer=%d,%d "
                  "view=%s split=%.3f image=%g,%g,%s%g probe=%s b=%s\n",
                  std::string(run_state_names.name(status.state)).c_str(), status.spp, status.target,
                  static_cast<unsigned long long>(model_.generation()), int(model_.dirty()), int(help_visible_),
                  int(panel_visible_), int(drags_[0].pressed) | 2 * int(drags_[1].pressed) | 4 * int(drags_[2].pressed) | 8 * int(divider_drag_), int(std::lround(io.MousePos.x)),
                  int(std::lround(io.MousePos.y)), std::string(view_mode_names.name(compare_.settings.mode)).c_str(),
                  compare_.settings.split, rect.x, rect.y, view_.fitted() ? "fit" : "", model_.has_scene() ? rect.width / model_.scene().renderer.width : 0.0,
                  probe, b);
    if (line == status_line_) return;
    try {
        write_file_atomic(*options_.status_file, line);
        status_line_ = line;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
    }
}

bool ViewerApp::script_step(const PixelRect& rect) {
    if (script_timed_out(options_, script_start_, Clock::now())) {
        script_status_ = 1;
        return true;
    }
    if (!model_.has_scene()) {
        std::fprintf(stderr, "error: %s\n", error_.c_str());
        script_status_ = 1;
        return true;
    }
    const bool current = shown_ && shown_->generation == model_.generation();
    if (latency_.running()) {
        if (const auto dx = latency_.on_frame(Clock::now(), current, current ? shown_->scale : 0)) {
            edit(Edit::camera, [&](Scene& s, ViewerSettings&) { orbit_drag(s.cameras[size_t(s.camera)], *dx, 0); });
            sync_worker();  // at once, as handle_input's edits are submitted in the same frame
        }
        if (latency_.running()) return false;
        std::fputs(latency_.report().c_str(), stdout);
        std::fflush(stdout);
    }
    // Without an image to write, the latency run is over; an idle run ends in idle_measure_step.
    if (!options_.writes_after_render()) return options_.measure_idle <= 0;
    // The screenshot waits for the render thread, never for time: N whole passes.
    const int needed = script_passes_needed(options_, model_.settings());
    if (!(current && shown_->scale == 1 && shown_->spp >= needed)) return false;
    try {
        if (options_.screenshot) {
            // What is on screen of the image: all of it unless zoomed in.
            const PixelRect area = view_area();
            const double x0 = std::max(rect.x, area.x), y0 = std::max(rect.y, area.y);
            const double x1 = std::min(rect.x + rect.width, area.x + area.width);
            const double y1 = std::min(rect.y + rect.height, area.y + area.height);
            write_image(*options_.screenshot, read_image_region({x0, y0, x1 - x0, y1 - y0}));
            const double scale = rect.width / model_.scene().renderer.width;
            std::printf("screenshot: %s (%d spp, generation %llu; image pixel %.6g,%.6g at %g screen pixels each)\n",
                        options_.screenshot->string().c_str(), shown_->spp,
                        static_cast<unsigned long long>(shown_->generation), (x0 - rect.x) / scale,
                        (y0 - rect.y) / scale, scale);
        }
        if (options_.stats_json) {
            write_file_atomic(*options_.stats_json, stats_json(stats_figures()));
            std::printf("stats: %s\n", options_.stats_json->string().c_str());
        }
        if (options_.save_image) {
            // The Save panel's code, without its overwrite question.
            const std::filesystem::path& out = *options_.save_image;
            save_output(image_save_kind(out), out, model_, shown_.get());
            std::printf("image: %s (%d spp)\n", out.string().c_str(), shown_->spp);
        }
        if (options_.save_scene) {
            save_scene_json(model_.scene_for_saving(), *options_.save_scene);
            std::printf("scene: %s\n", options_.save_scene->string().c_str());
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        script_status_ = 1;
    }
    std::fflush(stdout);
    return true;
}

bool ViewerApp::draw_frame() {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    fetch_frame();
    if (model_.has_scene() && inside_checked_generation_ != model_.generation()) {
        inside_checked_generation_ = model_.generation();
        inside_sphere_ = sphere_containing(model_.scene(), model_.camera().position);
    }
    if (!zoom_applied_ && model_.has_scene()) {
        zoom_applied_ = true;  // --zoom, about the image's centre, once the layout is known
        const int w = model_.scene().renderer.width, h = model_.scene().renderer.height;
        if (options_.zoom > 0) view_.set_zoom(view_area(), w, h, options_.zoom, w / 2.0, h / 2.0);
    }
    draw_panels();
    draw_status_bar();
    draw_help();
    draw_error_flash();
    handle_input();
    sync_worker();
    update_title();
    update_pictures();

    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    gl_.Viewport(0, 0, fb_w, fb_h);
    gl_.ClearColor(0.1f, 0.1f, 0.1f, 1.0f);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
    const PixelRect rect = image_rect();
    if (shown_) draw_image(rect, fb_w, fb_h);
    if (model_.has_scene()) draw_inspector(rect);
    // Scripted runs read the image region back here: what the shader drew, before
    // the panels are drawn over anything.
    const bool done = options_.scripted() && script_step(rect);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (done && options_.window_shot) {
        try {
            const Rgb8Image window = read_image_region({0, 0, double(fb_w), double(fb_h)});
            write_image(*options_.window_shot, window);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "error: %s\n", e.what());
            script_status_ = 1;
        }
    }
    glfwSwapBuffers(window_);
    return done;
}

bool ViewerApp::idle_measure_step() {
    const auto now = Clock::now();
    if (script_timed_out(options_, script_start_, now)) {
        script_status_ = 1;
        return true;
    }
    if (!model_.has_scene()) return false;  // script_step reports the error
    const RunStatus status = run_status(shown_ && shown_->generation == model_.generation() ? shown_.get() : nullptr,
                                        model_.settings(), false);
    const IdleMeasure::Step step = idle_.step(now, status.state == RunState::done);
    if (step == IdleMeasure::Step::pause) {
        edit(Edit::run_control, [](Scene&, ViewerSettings& s) {
            s.paused = true;
            s.unlimited = true;
        });
        sync_worker();
        input_seen_ = true;  // draw the new state once
    }
    return step == IdleMeasure::Step::finished;
}

int ViewerApp::run() {
    script_start_ = Clock::now();
    if (options_.scripted() && model_.has_scene()) {
        // The scripted edits go through the same functions as the mouse and the panels.
        const bool ok = apply_script_edits(options_, model_, [&](Edit kind, const auto& change) { return edit(kind, change); });
        if (!ok) return 1;
        if (options_.reference && !compare_.reference()) {
            std::fprintf(stderr, "error: %s\n", error_.c_str());
            return 1;
        }
    }
    last_frame_ = Clock::now();
    settle_frames_ = kSettleFrames;
    bool done = false;
    while (!done && !glfwWindowShouldClose(window_)) {
        poll_watch();
        sync_worker();
        if (options_.measure_idle > 0 && idle_measure_step()) break;
        const auto latest = worker_->latest();
        const bool new_snapshot = latest && latest->serial != shown_serial_;
        // Redraw only on input, a new snapshot, or something moving; else sleep until one of
        // those (the render thread and GLFW wake the wait) or the next poll of the scene file.
        if (!(input_seen_ || new_snapshot || settle_frames_ > 0 || animating())) {
            glfwWaitEventsTimeout(kWatchInterval);
            continue;
        }
        settle_frames_ = input_seen_ ? kSettleFrames : std::max(0, settle_frames_ - 1);
        input_seen_ = false;
        const auto frame_start = Clock::now();
        done = draw_frame();
        if (done) break;

        const auto now = Clock::now();
        const double work = seconds(now - frame_start);
        ui_work_ = ui_work_ > 0 ? 0.9 * ui_work_ + 0.1 * work : work;
        const double interval = seconds(now - last_frame_);
        last_frame_ = now;
        ui_fps_ = 0.9 * ui_fps_ + 0.1 * (interval > 0 ? 1.0 / interval : 0.0);
        if (shown_ && !shown_->finished) latency_.record_frame(work, interval);
        // Cap the UI rate where swap does not wait for vsync: the render thread needs the cores.
        // A new snapshot ends the wait early (the render thread posts an empty event).
        for (double left = kFrameInterval - seconds(Clock::now() - frame_start); left > 0.001;
             left = kFrameInterval - seconds(Clock::now() - frame_start)) {
            glfwWaitEventsTimeout(left);
            const auto newest = worker_->latest();
            if (newest && newest->serial != shown_serial_ && seconds(Clock::now() - frame_start) >= kMinFrameInterval)
                break;
        }
        glfwPollEvents();
    }
    return script_status_;
}

}  // namespace kr::viewer
