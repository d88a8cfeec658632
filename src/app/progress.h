// The terminal progress bar of `keithray render` and `keithray bench` (on stderr).
#pragma once

#include <string>

namespace kr {

// "12.3 s" below a minute, "4m05s" above.
std::string format_seconds(double seconds);

// Redraws one line: `[=====>    ]  42%  <what>  elapsed  ETA`, the ETA extrapolated from
// the fraction done so far.
void draw_progress(double fraction, const std::string& what, double elapsed);

}  // namespace kr
