#include "viewer/ui_app.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "core/image_io.h"
#include "scene/load.h"
#include "scene/save.h"
#include "viewer/navigation.h"

namespace kr::viewer {

namespace {

constexpr double kPanelWidth = 420;      // framebuffer pixels reserved for the panels
constexpr double kFrameInterval = 1.0 / 60;  // UI frame cap where there is no vsync (Xvfb)
constexpr double kMinFrameInterval = 1.0 / 120;  // ... and when a new snapshot cuts the wait short

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5))];
}

}  // namespace

ViewerApp::ViewerApp(ViewOptions options) : options_(std::move(options)) {
    model_.set_overrides(options_.overrides);
    model_.edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) {
        s.tone = options_.tone;
        s.unlimited = options_.unlimited;
        s.stop_seconds = options_.stop_seconds;
        s.stop_noise = options_.stop_noise;
    });
    try {
        model_.load(options_.scene);
    } catch (const SceneError& e) {
        error_ = e.what();
    }
    watch_.watch(options_.scene);
    reset_save_paths();

    if (!glfwInit()) throw std::runtime_error("cannot initialise GLFW (is there a display? try render --gl)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    const int w = model_.has_scene() ? model_.scene().renderer.width : 512;
    const int h = model_.has_scene() ? model_.scene().renderer.height : 512;
    // Room for the image at 1:1 when it is not huge, and the panels beside it.
    const int win_w = std::min(w, 1400) + int(kPanelWidth), win_h = std::max(std::min(h, 1000), 720);
    window_ = glfwCreateWindow(win_w, win_h, "keithray", nullptr, nullptr);
    if (!window_) {
        glfwTerminate();
        throw std::runtime_error("cannot open a window with an OpenGL 3.3 core context");
    }
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

bool ViewerApp::edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change) {
    std::string why;
    if (!model_.edit(kind, change, &why)) {
        error_ = why;
        return false;
    }
    if (edit_resets(kind)) {
        error_.clear();
        generation_edited_ = Clock::now();
    }
    return true;
}

void ViewerApp::open_scene(const std::filesystem::path& file) {
    try {
        model_.load(file);
        error_.clear();
        generation_edited_ = Clock::now();
        if (file != watch_.file()) {
            watch_.watch(file);
            reset_save_paths();
        }
    } catch (const SceneError& e) {
        error_ = e.what();  // the last good scene stays on screen
        if (!model_.has_scene()) watch_.watch(file);
    }
}

void ViewerApp::poll_watch() {
    if (watch_.changed()) open_scene(watch_.file());
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
        worker_->submit({submitted_generation_, model_.prepared(), s.render});
    }
}

void ViewerApp::fetch_frame() {
    std::shared_ptr<const Snapshot> frame = worker_->latest();
    if (!frame || frame->serial == shown_serial_) return;
    shown_serial_ = frame->serial;
    // A frame of an older generation shows an image the user already changed.
    if (frame->generation != model_.generation()) return;
    display_->upload(frame->radiance);
    shown_ = std::move(frame);
}

PixelRect ViewerApp::image_rect() const {
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    if (!model_.has_scene()) return {};
    const double w = model_.scene().renderer.width, h = model_.scene().renderer.height;
    const double area_w = std::max(1.0, fb_w - kPanelWidth), area_h = std::max(1.0, double(fb_h));
    double scale = std::min(area_w / w, area_h / h);
    // Whole pixels when it fits, so each image pixel is exactly one (or k x k) screen pixels.
    if (scale >= 1) scale = std::floor(scale);
    return {std::floor((area_w - w * scale) / 2), std::floor((area_h - h * scale) / 2), w * scale, h * scale};
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

void ViewerApp::handle_input() {
    if (!model_.has_scene()) return;
    ImGuiIO& io = ImGui::GetIO();
    const PixelRect rect = image_rect();
    const double to_fb = io.DisplayFramebufferScale.x;  // window points to framebuffer pixels
    const double image_scale = rect.width / model_.scene().renderer.width;
    // Mouse: only when ImGui does not want it, so a click on a panel never moves the camera.
    if (!io.WantCaptureMouse) {
        const double mx = io.MousePos.x * to_fb, my = io.MousePos.y * to_fb;
        const bool over_image =
            mx >= rect.x && my >= rect.y && mx < rect.x + rect.width && my < rect.y + rect.height;
        const double dx = io.MouseDelta.x * to_fb / image_scale, dy = io.MouseDelta.y * to_fb / image_scale;
        if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && over_image && (io.KeyCtrl || pick_focus_)) {
            const int w = model_.scene().renderer.width, h = model_.scene().renderer.height;
            const Vec2 film = raster_to_camera((mx - rect.x) / rect.width * w, (my - rect.y) / rect.height * h, w, h);
            if (!model_.focus_at(film.x, film.y))
                error_ = "click-to-focus: nothing there to focus on";
            else
                generation_edited_ = Clock::now();
            pick_focus_ = false;
        } else if (ImGui::IsMouseDragging(ImGuiMouseButton_Left, 0) && (dx != 0 || dy != 0) && !io.KeyCtrl) {
            edit(Edit::camera, [&](Scene& s, ViewerSettings&) { orbit_drag(s.cameras[size_t(s.camera)], dx, dy); });
        } else if (ImGui::IsMouseDragging(ImGuiMouseButton_Right, 0) && (dx != 0 || dy != 0)) {
            const int h = model_.scene().renderer.height;
            edit(Edit::camera, [&](Scene& s, ViewerSettings&) { pan_drag(s.cameras[size_t(s.camera)], dx, dy, h); });
        } else if (ImGui::IsMouseDragging(ImGuiMouseButton_Middle, 0) && dy != 0) {
            edit(Edit::camera, [&](Scene& s, ViewerSettings&) { dolly(s.cameras[size_t(s.camera)], std::exp(dy * 0.005)); });
        }
        if (io.MouseWheel != 0 && over_image)
            edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
                dolly(s.cameras[size_t(s.camera)], std::pow(0.9, double(io.MouseWheel)));
            });
    }
    if (io.WantCaptureKeyboard) return;
    // Keys: arrows orbit, W/S dolly, A/D/Q/E pan, F pick focus, Space pause.
    const double step = 8;  // pixels of drag per frame a key is held
    double ox = 0, oy = 0, px = 0, py = 0, zoom = 1;
    if (ImGui::IsKeyDown(GLFW_KEY_LEFT)) ox -= step;
    if (ImGui::IsKeyDown(GLFW_KEY_RIGHT)) ox += step;
    if (ImGui::IsKeyDown(GLFW_KEY_UP)) oy -= step;
    if (ImGui::IsKeyDown(GLFW_KEY_DOWN)) oy += step;
    if (ImGui::IsKeyDown(GLFW_KEY_A)) px += step;
    if (ImGui::IsKeyDown(GLFW_KEY_D)) px -= step;
    if (ImGui::IsKeyDown(GLFW_KEY_Q)) py -= step;
    if (ImGui::IsKeyDown(GLFW_KEY_E)) py += step;
    if (ImGui::IsKeyDown(GLFW_KEY_W)) zoom *= 0.97;
    if (ImGui::IsKeyDown(GLFW_KEY_S)) zoom /= 0.97;
    if (ox != 0 || oy != 0 || px != 0 || py != 0 || zoom != 1) {
        const int h = model_.scene().renderer.height;
        edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera& cam = s.cameras[size_t(s.camera)];
            if (ox != 0 || oy != 0) orbit_drag(cam, ox, oy);
            if (px != 0 || py != 0) pan_drag(cam, px, py, h);
            if (zoom != 1) dolly(cam, zoom);
        });
    }
    if (ImGui::IsKeyPressed(GLFW_KEY_F, false)) pick_focus_ = !pick_focus_;
    if (ImGui::IsKeyPressed(GLFW_KEY_SPACE, false))
        edit(Edit::run_control, [](Scene&, ViewerSettings& s) { s.paused = !s.paused; });
}

bool ViewerApp::script_step(const PixelRect& rect) {
    if (seconds(Clock::now() - script_start_) > options_.timeout) {
        std::fprintf(stderr, "error: scripted run did not finish within %.0f s\n", options_.timeout);
        script_status_ = 1;
        return true;
    }
    if (!model_.has_scene()) {
        std::fprintf(stderr, "error: %s\n", error_.c_str());
        script_status_ = 1;
        return true;
    }
    const bool current = shown_ && shown_->generation == model_.generation();
    if (options_.measure_latency > 0 && latency_edits_done_ < options_.measure_latency) {
        const auto now = Clock::now();
        if (latency_waiting_for_) {
            // The frame drawn this iteration is the first of the edited generation.
            if (current) {
                latencies_.push_back(seconds(now - latency_edit_time_));
                latency_scales_.push_back(shown_->scale);
                latency_waiting_for_.reset();
                ++latency_edits_done_;
                latency_next_edit_ = now + std::chrono::milliseconds(300);
            }
        } else if (current && shown_->scale == 1 && now >= latency_next_edit_) {
            // An orbit nudge, as a mouse drag would make, while full-resolution passes run.
            latency_edit_time_ = now;
            const double dx = (latency_edits_done_ % 2 == 0) ? 4 : -4;
            edit(Edit::camera, [&](Scene& s, ViewerSettings&) { orbit_drag(s.cameras[size_t(s.camera)], dx, 0); });
            latency_waiting_for_ = model_.generation();
            sync_worker();  // at once, as handle_input's edits are submitted in the same frame
        }
        if (latency_edits_done_ < options_.measure_latency) return false;
        std::printf("latency (edit -> first frame of the new image drawn), %zu edits: median %.1f ms, "
                    "90th percentile %.1f ms, max %.1f ms; coarsest preview: 1/%d\n",
                    latencies_.size(), 1e3 * percentile(latencies_, 0.5), 1e3 * percentile(latencies_, 0.9),
                    1e3 * percentile(latencies_, 1.0),
                    latency_scales_.empty() ? 1 : *std::max_element(latency_scales_.begin(), latency_scales_.end()));
        std::printf("UI frame interval while rendering: median %.1f ms, 95th percentile %.1f ms, max %.1f ms "
                    "(%zu frames)\n",
                    1e3 * percentile(frame_intervals_, 0.5), 1e3 * percentile(frame_intervals_, 0.95),
                    1e3 * percentile(frame_intervals_, 1.0), frame_intervals_.size());
        std::printf("UI frame work (events, panels, upload, draw, swap): median %.1f ms, 95th percentile %.1f ms\n",
                    1e3 * percentile(frame_work_, 0.5), 1e3 * percentile(frame_work_, 0.95));
        std::fflush(stdout);
        if (!options_.screenshot && !options_.save_scene && options_.frames == 0) return true;
    }
    // The screenshot waits for the render thread, never for time: N whole passes.
    const int target = model_.settings().render.target_spp;
    const int needed = options_.frames > 0 ? (model_.settings().unlimited ? options_.frames
                                                                          : std::min(options_.frames, target))
                                           : target;
    if (!(current && shown_->scale == 1 && shown_->spp >= needed)) return false;
    try {
        if (options_.screenshot) {
            write_image(*options_.screenshot, read_image_region(rect));
            std::printf("screenshot: %s (%d spp, generation %llu)\n", options_.screenshot->string().c_str(),
                        shown_->spp, static_cast<unsigned long long>(shown_->generation));
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

int ViewerApp::run() {
    script_start_ = Clock::now();
    if (options_.scripted() && model_.has_scene()) {
        // The scripted edits go through the same functions as the mouse and the panels.
        if (options_.aperture)
            edit(Edit::lens, [&](Scene& s, ViewerSettings&) {
                Camera& cam = s.cameras[size_t(s.camera)];
                cam.type = CameraType::lens;
                cam.alpha = *options_.aperture;
            });
        if (options_.orbit)
            edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
                orbit_drag(s.cameras[size_t(s.camera)], options_.orbit->first, options_.orbit->second);
            });
        if (options_.click_focus) {
            const Vec2 film = raster_to_camera(options_.click_focus->first + 0.5, options_.click_focus->second + 0.5,
                                               model_.scene().renderer.width, model_.scene().renderer.height);
            if (!model_.focus_at(film.x, film.y)) {
                std::fprintf(stderr, "error: --click-focus: the ray through that pixel hits nothing\n");
                return 1;
            }
            std::printf("focal distance: %.17g\n", model_.camera().focal_distance);
        }
    }
    last_frame_ = Clock::now();
    while (!glfwWindowShouldClose(window_)) {
        const auto frame_start = Clock::now();
        glfwPollEvents();
        poll_watch();
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        draw_panels();
        handle_input();
        sync_worker();
        fetch_frame();

        int fb_w = 0, fb_h = 0;
        glfwGetFramebufferSize(window_, &fb_w, &fb_h);
        gl_.Viewport(0, 0, fb_w, fb_h);
        gl_.ClearColor(0.1f, 0.1f, 0.1f, 1.0f);
        gl_.Clear(GL_COLOR_BUFFER_BIT);
        const PixelRect rect = image_rect();
        if (shown_) display_->draw(rect, fb_w, fb_h, model_.settings().tone);
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
        if (done) break;

        // Cap the UI rate where swap does not wait for vsync: the render thread needs the cores.
        const auto now = Clock::now();
        const double work = seconds(now - frame_start);
        ui_work_ = ui_work_ > 0 ? 0.9 * ui_work_ + 0.1 * work : work;
        if (shown_ && !shown_->finished && frame_work_.size() < 100000) frame_work_.push_back(work);
        const double interval = seconds(now - last_frame_);
        last_frame_ = now;
        ui_fps_ = 0.9 * ui_fps_ + 0.1 * (interval > 0 ? 1.0 / interval : 0.0);
        if (shown_ && !shown_->finished && frame_intervals_.size() < 100000) frame_intervals_.push_back(interval);
        // A new snapshot ends the wait early (the render thread posts an empty event).
        for (double left = kFrameInterval - seconds(Clock::now() - frame_start); left > 0.001;
             left = kFrameInterval - seconds(Clock::now() - frame_start)) {
            glfwWaitEventsTimeout(left);
            const auto latest = worker_->latest();
            if (latest && latest->serial != shown_serial_ && seconds(Clock::now() - frame_start) >= kMinFrameInterval)
                break;
        }
    }
    return script_status_;
}

}  // namespace kr::viewer
