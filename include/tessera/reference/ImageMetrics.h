#pragma once
#include "tessera/core/Image.h"

namespace tessera {

// Peak signal-to-noise ratio over the RGB channels (alpha ignored), in dB,
// peak 255. Identical images give +infinity. Images must have equal, non-zero
// sizes (InputError otherwise).
double psnr(const Image& a, const Image& b);

// Mean structural similarity (Wang et al. 2004) of the luminance
// (0.299R + 0.587G + 0.114B), 11x11 Gaussian window sigma 1.5,
// K1 = 0.01, K2 = 0.03, L = 255. 1.0 for identical images.
// Averaged over the 'valid' window positions (no padding), as in the
// authors' reference code; an image under 11 px along an axis uses a window
// of the image's size along it. InputError for unequal sizes or empty images.
double ssim(const Image& a, const Image& b);

}  // namespace tessera
