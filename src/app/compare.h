// `keithray psnr` and `keithray compare` (compare.cpp).
#pragma once

namespace kr {

// argv[1] is "psnr": IMAGE REFERENCE. PSNR of 8-bit images, RMSE and relative MSE of two HDR
// ones. Returns the exit status.
int run_psnr(int argc, char** argv);
// argv[1] is "compare": TEST REFERENCE with thresholds or --statistical. 0 when the images
// agree, 1 when they do not (or a file is bad), 2 on bad usage.
int run_compare(int argc, char** argv);

// Their help texts (`keithray compare --help`, `keithray psnr --help`), which the man page
// and the shell completion are made from (app/docs.h).
const char* compare_usage();
const char* psnr_usage();

}  // namespace kr
