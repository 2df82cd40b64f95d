// Ray rates as rtcl prints them: in Mrays/s with three significant digits
// at least, so that a small rate never reads "0.00".
#pragma once

#include <string>

namespace rtcl::cli {

// A rate in Mrays/s as text: "412", "41.2", "4.12", "0.412", "0.00412";
// "0" for 0, "-" for a rate that is not a finite number.
std::string mrays_text(double mrays_per_s);

// `rays` traced in `ms` milliseconds, in Mrays/s as text (mrays_text): "0"
// for no rays, "-" when no time was measured (ms <= 0: a timer too coarse
// for a tiny launch).
std::string mrays_text(double rays, double ms);

}  // namespace rtcl::cli
