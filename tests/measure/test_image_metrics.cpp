#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "measure/image_metrics.hpp"

using namespace lodstream;

namespace {
Image gray(int w, int h, uint8_t value) {
  Image img(w, h);
  for (size_t i = 0; i < img.rgba.size(); i += 4) {
    img.rgba[i] = img.rgba[i + 1] = img.rgba[i + 2] = value;
    img.rgba[i + 3] = 255;
  }
  return img;
}

Image noise(int w, int h, unsigned seed) {
  Image img(w, h);
  std::mt19937 rng(seed);
  for (auto& byte : img.rgba) byte = uint8_t(rng() & 0xff);
  return img;
}
}  // namespace

TEST(Psnr, ConstantOffset) {
  // Every channel differs by 10: MSE = 100, PSNR = 10·log10(255²/100) = 28.1308 dB.
  EXPECT_NEAR(psnr(gray(7, 5, 100), gray(7, 5, 110)), 28.1308036, 1e-6);
  // Only red differs by 10: MSE = 100/3, PSNR = 10·log10(3·255²/100) = 32.9020 dB; alpha is ignored.
  Image a = gray(4, 4, 50), b = gray(4, 4, 50);
  for (size_t i = 0; i < b.rgba.size(); i += 4) {
    b.rgba[i] = 60;
    b.rgba[i + 3] = 0;
  }
  EXPECT_NEAR(psnr(a, b), 32.9020162, 1e-6);
}

TEST(Psnr, IdenticalIsInfiniteAndSizesMustMatch) {
  Image a = noise(9, 9, 1);
  EXPECT_TRUE(std::isinf(psnr(a, a)));
  EXPECT_THROW(psnr(a, noise(9, 8, 1)), Error);
  EXPECT_THROW(psnr(Image{}, Image{}), Error);
}

TEST(Ssim, IdenticalIsOneAndSymmetric) {
  Image a = noise(40, 30, 1), b = noise(40, 30, 2);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
  double s = ssim(a, b);
  EXPECT_LT(s, 0.1);  // independent noise has almost no structure in common
  EXPECT_DOUBLE_EQ(s, ssim(b, a));
}

TEST(Ssim, ConstantImages) {
  // No variance: SSIM = (2ab + C1) / (a² + b² + C1) at every position; a = 100, b = 150, C1 = 6.5025:
  // (30000 + 6.5025) / (32500 + 6.5025) = 0.9230923.
  EXPECT_NEAR(ssim(gray(20, 15, 100), gray(20, 15, 150)), 0.9230923, 1e-7);
}

TEST(Ssim, OneBrightPixelByHand) {
  // 11x11 images: one window position. x = 100 everywhere except the centre pixel, 200; y = 100 everywhere.
  // Gaussian weights: the 1-D sum is Σ_{k=-5..5} exp(−k²/4.5) = 3.7592328, so the centre's 2-D weight is
  // w = 1/3.7592328² = 0.0707622. Then μx = 100 + 100w = 107.07622, μy = 100, σx² = w(1−w)·100² = 657.5494,
  // σy² = σxy = 0; with C1 = 6.5025 and C2 = 58.5225:
  // SSIM = (2·107.07622·100 + C1)·C2 / ((107.07622² + 100² + C1)·(657.5494 + C2)) = 0.0815365.
  Image x = gray(11, 11, 100), y = gray(11, 11, 100);
  uint8_t* centre = x.pixel(5, 5);
  centre[0] = centre[1] = centre[2] = 200;
  EXPECT_NEAR(ssim(x, y), 0.0815365, 1e-6);
}

TEST(Ssim, UsesLuminance) {
  // Moving the bright pixel's excess from grey to pure green changes only its luminance: 100 + 0.587·100
  // instead of 200; two images that differ only in hue at equal luminance are identical to SSIM.
  Image x = gray(11, 11, 100), y = gray(11, 11, 100);
  uint8_t* px = x.pixel(3, 7);
  px[0] = 0;
  px[1] = 100;
  px[2] = 0;  // Y = 58.7
  uint8_t* py = y.pixel(3, 7);
  py[0] = 196;
  py[1] = 0;
  py[2] = 0;  // Y = 58.604: almost the same luminance, very different colour
  EXPECT_GT(ssim(x, y), 0.9999);
  EXPECT_LT(psnr(x, y), 40.0);
}

TEST(Ssim, BadSizesAreErrors) {
  EXPECT_THROW(ssim(gray(20, 20, 1), gray(20, 21, 1)), Error);
  EXPECT_THROW(ssim(gray(10, 20, 1), gray(10, 20, 1)), Error);
}
