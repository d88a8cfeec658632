#include "viewer/convergence_log.h"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>
#include "core/text.h"

namespace kr::viewer {

void ConvergenceLog::record(const Snapshot& frame, const std::optional<CompareFigures>& figures) {
    if (frame.generation != generation_) {
        generation_ = frame.generation;
        points_.clear();
    }
    if (frame.scale != 1 || frame.spp <= 0) return;
    if (!points_.empty() && points_.back().spp == frame.spp) {
        // The same passes again (a tone-map change or a new reference): newest figures.
        if (figures) points_.back().rmse = figures->rmse, points_.back().psnr = figures->psnr;
        return;
    }
    ConvergencePoint p;
    p.seconds = frame.full_seconds;
    p.spp = frame.spp;
    p.estimated = frame.relative_error;
    if (figures) p.rmse = figures->rmse, p.psnr = figures->psnr;
    points_.push_back(p);
}

std::string ConvergenceLog::csv() const {
    std::string out = "seconds,spp,estimated_relative_error,rmse,psnr\n";
    char line[160];
    for (const ConvergencePoint& p : points_) {
        auto cell = [](double v, bool known) {
            char b[32] = "";
            if (known) std::snprintf(b, sizeof b, "%.9g", v);
            return std::string(b);
        };
        std::snprintf(line, sizeof line, "%.6f,%d,%s,%s,%s\n", p.seconds, p.spp,
                      cell(p.estimated, std::isfinite(p.estimated)).c_str(), cell(p.rmse, p.rmse >= 0).c_str(),
                      cell(p.psnr, p.psnr >= 0).c_str());
        out += line;
    }
    return out;
}

std::string stats_json(const StatsFigures& s) {
    nlohmann::ordered_json j;
    j["state"] = s.state;
    j["spp"] = s.spp;
    j["target_spp"] = s.target;
    j["elapsed_seconds"] = s.elapsed;
    j["mrays_per_second"] = s.mrays_per_second;
    j["noise"] = s.noise >= 0 && std::isfinite(s.noise) ? nlohmann::ordered_json(s.noise) : nlohmann::ordered_json();
    // Image A, of which psnr and rmse are figures: the image the window shows.
    if (!s.image.empty()) j["image"] = s.image;
    if (s.reference) j["reference"] = utf8_escaped(*s.reference);  // a file name need not be UTF-8
    if (s.figures) {
        j["psnr"] = s.figures->psnr;
        j["rmse"] = s.figures->rmse;
    }
    if (s.probe) {
        const PixelProbe& p = *s.probe;
        auto& probe = j["probe"];
        probe["x"] = p.x;
        probe["y"] = p.y;
        probe["mean"] = {p.mean.x, p.mean.y, p.mean.z};
        probe["displayed"] = {p.displayed[0], p.displayed[1], p.displayed[2]};
        probe["samples"] = p.samples;
        probe["standard_error"] = std::isfinite(p.standard_error) ? nlohmann::ordered_json(p.standard_error)
                                                                 : nlohmann::ordered_json();
    }
    return j.dump(2) + "\n";
}

}  // namespace kr::viewer
