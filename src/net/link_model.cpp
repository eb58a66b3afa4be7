#include "net/link_model.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "core/error.hpp"

namespace lodstream {

namespace {
// Splits "12.5mbit" into 12.5 and "mbit"; false when the number part is not a finite non-negative number.
bool split_number(const std::string& text, double& value, std::string& unit) {
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || !std::isfinite(value) || value < 0) return false;
  unit.assign(ptr, text.data() + text.size());
  return true;
}
}  // namespace

double parse_bandwidth(const std::string& text, const std::string& option) {
  double value = 0;
  std::string unit;
  if (split_number(text, value, unit)) {
    double scale = unit == "" || unit == "bit" ? 1.0
                   : unit == "kbit"            ? 1e3
                   : unit == "mbit"            ? 1e6
                   : unit == "gbit"            ? 1e9
                                               : 0.0;
    if (scale > 0 && value * scale >= 1e3 && value * scale <= 1e11) return value * scale;
  }
  throw Error(option + " must be a bandwidth between 1kbit and 100gbit such as 10mbit or 500kbit, got '" +
              text + "'");
}

double parse_duration(const std::string& text, const std::string& option) {
  double value = 0;
  std::string unit;
  if (split_number(text, value, unit)) {
    double scale = unit == "" || unit == "ms" ? 1e-3 : unit == "s" ? 1.0 : unit == "us" ? 1e-6 : 0.0;
    if (scale > 0 && value * scale <= 60.0) return value * scale;
  }
  throw Error(option + " must be a duration up to 60s such as 80ms, 0.5s or 500us, got '" + text + "'");
}

LinkDirection::LinkDirection(const LinkSettings& settings) : settings_(settings), random_(settings.seed) {}

double LinkDirection::send(double now_s, size_t bytes) {
  busy_until_ = std::max(now_s, busy_until_) + 8.0 * double(bytes) / settings_.bandwidth_bps;
  double delay = settings_.rtt_s / 2;
  if (settings_.jitter_s > 0) {
    std::uniform_real_distribution<double> jitter(-settings_.jitter_s, settings_.jitter_s);
    delay = std::max(0.0, delay + jitter(random_));
  }
  last_delivery_ = std::max(last_delivery_, busy_until_ + delay);
  return last_delivery_;
}

}  // namespace lodstream
