#include "viewer/script.h"

#include <algorithm>
#include <cstdio>

#include <sys/resource.h>

#include "render/trace.h"
#include "viewer/navigation.h"

namespace kr::viewer {

namespace {

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

bool apply_script_edits(const ViewOptions& options, ViewerModel& model, const EditFunction& edit) {
    if (options.aperture)
        edit(Edit::lens, [&](Scene& s, ViewerSettings&) {
            Camera& cam = s.cameras[size_t(s.camera)];
            cam.type = CameraType::lens;
            cam.alpha = *options.aperture;
        });
    if (options.orbit)
        edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            // The window's drag about the target, stopped at surfaces as it is there.
            Camera& cam = s.cameras[size_t(s.camera)];
            cam = orbit_step(s, cam, cam.target, options.orbit->first, options.orbit->second, true);
        });
    if (options.click_focus) {
        // The centre of the pixel, as a click on it gives.
        const Vec2 film = raster_to_camera(options.click_focus->first + 0.5, options.click_focus->second + 0.5,
                                           model.scene().renderer.width, model.scene().renderer.height);
        if (!model.focus_at(film.x, film.y)) {
            std::fprintf(stderr, "error: --click-focus: the ray through that pixel hits nothing\n");
            return false;
        }
        std::printf("focal distance: %.17g\n", model.camera().focal_distance);
    }
    return true;
}

int script_passes_needed(const ViewOptions& options, const ViewerSettings& settings) {
    const int target = settings.render.target_spp;
    if (options.frames <= 0) return target;
    return settings.unlimited ? options.frames : std::min(options.frames, target);
}

bool script_timed_out(const ViewOptions& options, std::chrono::steady_clock::time_point start,
                      std::chrono::steady_clock::time_point now) {
    if (seconds(now - start) <= options.timeout) return false;
    std::fprintf(stderr, "error: scripted run did not finish within %.0f s\n", options.timeout);
    return true;
}

double process_cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

IdleMeasure::Step IdleMeasure::step(Clock::time_point now, bool done) {
    const double settle = 1.0;  // seconds between a change of state and its measurement
    const double elapsed = seconds(now - phase_start_);
    if (phase_ == 0) {
        if (done) {
            phase_ = 1;
            phase_start_ = now;
        }
        return Step::wait;
    }
    if (phase_ == 1 || phase_ == 3) {
        if (elapsed < settle) return Step::wait;
        cpu_start_ = process_cpu_seconds();
        phase_start_ = now;
        ++phase_;
        return Step::wait;
    }
    if (elapsed < seconds_) return Step::wait;
    const double cpu = process_cpu_seconds() - cpu_start_;
    const bool paused = phase_ == 4;
    std::printf("idle CPU, %s: %.2f%% of a core over %.1f s\n", paused ? "paused" : "done", 100 * cpu / elapsed, elapsed);
    std::fflush(stdout);
    if (paused) return Step::finished;
    // Then paused with unlimited refinement: the render thread waits, the window sleeps.
    phase_ = 3;
    phase_start_ = now;
    return Step::pause;
}

}  // namespace kr::viewer
