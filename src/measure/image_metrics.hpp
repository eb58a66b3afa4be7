// Image fidelity metrics between two 8-bit RGBA images of the same size (alpha is ignored).
#pragma once

#include "core/image.hpp"

namespace lodstream {

// Peak signal-to-noise ratio over R, G and B: PSNR = 10·log10(255² / MSE), MSE the mean of the squared
// differences over all pixels and the three channels. +infinity for identical images. Throws lodstream::Error
// when the sizes differ or the images are empty. Cost: O(W·H).
double psnr(const Image& a, const Image& b);

// Mean structural similarity (Wang, Bovik, Sheikh, Simoncelli 2004, eq. 13 with the paper's parameters): on
// luminance Y = 0.299R + 0.587G + 0.114B (unrounded), with local statistics weighted by an 11×11 Gaussian
// window (σ = 1.5, normalized to sum 1),
//   SSIM(x,y) = (2·μx·μy + C1)(2·σxy + C2) / ((μx² + μy² + C1)(σx² + σy² + C2)),  C1 = (0.01·255)², C2 =
//   (0.03·255)²,
// averaged over every position where the window lies wholly inside the image ("valid" positions, as the
// authors' ssim_index.m does with filter2(..., 'valid')): no padding, so (W−10)·(H−10) positions. 1 for
// identical images. Throws lodstream::Error when the sizes differ or either side is smaller than 11 pixels.
// Cost: O(W·H·11) (separable filtering of five moment images), about 5·W·H doubles of memory.
double ssim(const Image& a, const Image& b);

}  // namespace lodstream
