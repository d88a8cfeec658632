#include "app/progress.h"

#include <algorithm>
#include <cstdio>

namespace kr {

std::string format_seconds(double s) {
    char buf[32];
    if (s < 60) std::snprintf(buf, sizeof buf, "%.1f s", s);
    else std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    return buf;
}

void draw_progress(double fraction, const std::string& what, double elapsed) {
    constexpr int kWidth = 30;
    fraction = std::clamp(fraction, 0.0, 1.0);
    const int filled = int(fraction * kWidth);
    std::string bar(filled, '=');
    if (filled < kWidth) bar += '>' + std::string(kWidth - filled - 1, ' ');
    const std::string eta = fraction > 0 ? format_seconds(elapsed * (1 - fraction) / fraction) : "?";
    std::fprintf(stderr, "\r  [%s] %3d%%  %s  %s  ETA %s   ", bar.c_str(), int(fraction * 100), what.c_str(),
                 format_seconds(elapsed).c_str(), eta.c_str());
    std::fflush(stderr);
}

}  // namespace kr
