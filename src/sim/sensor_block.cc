#include "pf_localization/sim/sensor_block.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace pf::sim {

namespace {

double seconds(const std::string& text, const std::string& whole) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    throw std::invalid_argument("bad time '" + text + "' in '" + whole + "'");
  }
  return v;
}

}  // namespace

SensorBlock parseSensorBlock(const std::string& text) {
  const std::size_t first = text.find(':');
  const std::size_t second = first == std::string::npos ? first : text.find(':', first + 1);
  if (second == std::string::npos || text.find(':', second + 1) != std::string::npos) {
    throw std::invalid_argument("'" + text + "' is not NAME:T0:T1");
  }
  SensorBlock block;
  block.sensor = text.substr(0, first);
  if (block.sensor.empty()) throw std::invalid_argument("no sensor name in '" + text + "'");
  const double t0 = seconds(text.substr(first + 1, second - first - 1), text);
  const double t1 = seconds(text.substr(second + 1), text);
  if (t0 < 0.0 || !(t0 < t1)) {
    throw std::invalid_argument("'" + text + "' needs 0 <= T0 < T1");
  }
  block.from_ns = std::llround(t0 * 1e9);
  block.to_ns = std::llround(t1 * 1e9);
  return block;
}

std::vector<float> coveredReadings(int beams, double range_min) {
  return std::vector<float>(beams, static_cast<float>(range_min));
}

}  // namespace pf::sim
