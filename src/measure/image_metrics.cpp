#include "measure/image_metrics.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace lodstream {

namespace {
void check_same_size(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    throw Error("images differ in size: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " and " + std::to_string(b.width) + "x" + std::to_string(b.height));
}

constexpr int window = 11;
constexpr double sigma = 1.5;

std::vector<double> luminance(const Image& image) {
  std::vector<double> y(size_t(image.width) * size_t(image.height));
  for (size_t i = 0; i < y.size(); ++i) {
    const uint8_t* p = &image.rgba[4 * i];
    y[i] = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
  }
  return y;
}

// Valid-region filtering of a W×H image with the separable kernel g⊗g: (W−10)×(H−10) output.
std::vector<double> filter_valid(const std::vector<double>& in, int w, int h, const double* g) {
  const int ow = w - window + 1, oh = h - window + 1;
  std::vector<double> rows(size_t(ow) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < ow; ++x) {
      double s = 0;
      for (int k = 0; k < window; ++k) s += g[k] * in[size_t(y) * size_t(w) + size_t(x + k)];
      rows[size_t(y) * size_t(ow) + size_t(x)] = s;
    }
  std::vector<double> out(size_t(ow) * size_t(oh));
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      double s = 0;
      for (int k = 0; k < window; ++k) s += g[k] * rows[size_t(y + k) * size_t(ow) + size_t(x)];
      out[size_t(y) * size_t(ow) + size_t(x)] = s;
    }
  return out;
}
}  // namespace

double psnr(const Image& a, const Image& b) {
  check_same_size(a, b);
  if (a.width <= 0 || a.height <= 0) throw Error("PSNR of empty images");
  uint64_t sum = 0;  // at most 3·255²·W·H: fits for any image up to 16384² pixels
  for (size_t i = 0; i < a.rgba.size(); i += 4)
    for (size_t c = 0; c < 3; ++c) {
      const int d = int(a.rgba[i + c]) - int(b.rgba[i + c]);
      sum += uint64_t(d * d);
    }
  if (sum == 0) return std::numeric_limits<double>::infinity();
  const double mse = double(sum) / (3.0 * double(a.width) * double(a.height));
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

double ssim(const Image& a, const Image& b) {
  check_same_size(a, b);
  if (a.width < window || a.height < window)
    throw Error("SSIM needs images of at least 11x11 pixels, got " + std::to_string(a.width) + "x" +
                std::to_string(a.height));
  // 1-D Gaussian, normalized so that the 2-D window g⊗g sums to 1.
  double g[window], total = 0;
  for (int k = 0; k < window; ++k)
    total += g[k] = std::exp(-double((k - 5) * (k - 5)) / (2.0 * sigma * sigma));
  for (double& v : g) v /= total;

  const int w = a.width, h = a.height;
  const std::vector<double> x = luminance(a), y = luminance(b);
  std::vector<double> xx(x.size()), yy(x.size()), xy(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  const std::vector<double> mu_x = filter_valid(x, w, h, g), mu_y = filter_valid(y, w, h, g);
  const std::vector<double> e_xx = filter_valid(xx, w, h, g), e_yy = filter_valid(yy, w, h, g),
                            e_xy = filter_valid(xy, w, h, g);

  constexpr double C1 = (0.01 * 255) * (0.01 * 255), C2 = (0.03 * 255) * (0.03 * 255);
  double sum = 0;
  for (size_t i = 0; i < mu_x.size(); ++i) {
    // Weighted moments: σx² = E[x²] − μx², σxy = E[xy] − μx·μy (Wang et al. eqs. 14–16 with window weights
    // w_i).
    const double mx = mu_x[i], my = mu_y[i];
    const double sxx = e_xx[i] - mx * mx, syy = e_yy[i] - my * my, sxy = e_xy[i] - mx * my;
    sum += (2 * mx * my + C1) * (2 * sxy + C2) / ((mx * mx + my * my + C1) * (sxx + syy + C2));
  }
  return sum / double(mu_x.size());
}

}  // namespace lodstream
