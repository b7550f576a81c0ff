#pragma once
// Image quality of a rendered colour image against the captured one, colours in [0,1].
//   PSNR = 10·log10(1 / MSE), peak 1, MSE over the 3 channels of the included pixels;
//          +inf when the images are identical.
//   SSIM exactly as 3DGS utils/loss_utils.py ssim(): 11×11 Gaussian window (σ = 1.5, normalised),
//        per channel, 'same' size with zero padding (F.conv2d padding=5), C1 = 0.01², C2 = 0.03²,
//        then the mean of the SSIM map over channels and included pixels.
// A mask, when given, must have the image's size; a non-zero pixel is included. All functions
// throw std::invalid_argument on a size mismatch, empty images, or a mask that includes nothing.
#include "core/common/image.h"

#include <array>
#include <vector>

namespace rrg::eval {

inline constexpr int kSsimWindow = 11;     // window side
inline constexpr double kSsimSigma = 1.5;  // Gaussian σ in pixels
inline constexpr double kSsimC1 = 0.01 * 0.01;
inline constexpr double kSsimC2 = 0.03 * 0.03;

// The normalised 1-D Gaussian g[k] ∝ exp(−(k − 5)² / (2σ²)); the 2-D window is g gᵀ.
std::array<double, kSsimWindow> ssim_gaussian_1d();

// Mean squared error over the 3 channels of the included pixels.
double mean_squared_error(const ColorImage& est, const ColorImage& ref, const MaskImage* mask = nullptr);
// PSNR in dB with peak 1; +inf when the MSE is 0.
double psnr(const ColorImage& est, const ColorImage& ref, const MaskImage* mask = nullptr);
// Per-pixel, per-channel SSIM map, index (y·W + x)·3 + c.
std::vector<double> ssim_map(const ColorImage& est, const ColorImage& ref);
// Mean of ssim_map over all channels of the included pixels.
double ssim(const ColorImage& est, const ColorImage& ref, const MaskImage* mask = nullptr);

}  // namespace rrg::eval
