#include "valvefsi/case/pressure_waveform.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "valvefsi/case/case_loader.hpp"

namespace valvefsi {

PressureWaveform::PressureWaveform(const cases::PressureWaveform& table,
                                   const std::string& source_name)
    : period_(table.has_period_s() ? table.period_s() : 0.8),
      scale_(table.has_scale() ? table.scale() : 1.0),
      ramp_time_(table.ramp_time()) {
  const int n = table.time_s_size();
  if (n < 2) {
    throw CaseError(fmt::format("{}: field 'waveform.time_s' has {} samples; at least 2 are needed",
                                source_name, n));
  }
  if (table.ventricular_pressure_mmhg_size() != n || table.aortic_pressure_mmhg_size() != n) {
    throw CaseError(fmt::format(
        "{}: 'waveform.time_s' has {} samples but 'ventricular_pressure_mmHg' has {} and "
        "'aortic_pressure_mmHg' {}; all three must have the same length",
        source_name, n, table.ventricular_pressure_mmhg_size(), table.aortic_pressure_mmhg_size()));
  }
  if (!(period_ > 0.0)) {
    throw CaseError(fmt::format("{}: field 'waveform.period_s' = {}; allowed: > 0", source_name,
                                period_));
  }
  for (int i = 0; i < n; ++i) {
    const double t = table.time_s(i);
    if (!(t >= 0.0 && t < period_) || (i > 0 && !(t > table.time_s(i - 1)))) {
      throw CaseError(fmt::format(
          "{}: field 'waveform.time_s[{}]' = {}; times must increase strictly within [0, {})",
          source_name, i, t, period_));
    }
    for (const auto& [name, value] :
         {std::pair{"ventricular_pressure_mmHg", table.ventricular_pressure_mmhg(i)},
          std::pair{"aortic_pressure_mmHg", table.aortic_pressure_mmhg(i)}}) {
      if (!std::isfinite(value)) {
        throw CaseError(fmt::format("{}: field 'waveform.{}[{}]' = {} is not a finite number",
                                    source_name, name, i, value));
      }
    }
    time_.push_back(t);
    ventricular_Pa_.push_back(table.ventricular_pressure_mmhg(i) * kPascalPerMmHg);
    aortic_Pa_.push_back(table.aortic_pressure_mmhg(i) * kPascalPerMmHg);
  }
}

double PressureWaveform::interpolate(const std::vector<double>& values_Pa, double t) const {
  double phase = std::fmod(t, period_);
  if (phase < 0.0) phase += period_;
  // Past the last sample the curve closes onto the first one of the next cycle.
  const auto upper = std::upper_bound(time_.begin(), time_.end(), phase);
  const std::size_t hi = static_cast<std::size_t>(upper - time_.begin());
  const std::size_t i1 = hi % time_.size();
  const std::size_t i0 = (hi + time_.size() - 1) % time_.size();
  double t0 = time_[i0];
  double t1 = time_[i1];
  if (hi == 0) t0 -= period_;
  if (hi == time_.size()) t1 += period_;
  const double w = (t1 > t0) ? (phase - t0) / (t1 - t0) : 0.0;
  return (1.0 - w) * values_Pa[i0] + w * values_Pa[i1];
}

double PressureWaveform::ramp_factor(double t) const {
  if (ramp_time_ <= 0.0 || t >= ramp_time_) return 1.0;
  if (t <= 0.0) return 0.0;
  return 0.5 * (1.0 - std::cos(std::numbers::pi * t / ramp_time_));
}

double PressureWaveform::ventricular_pressure(double t) const {
  return interpolate(ventricular_Pa_, t);
}
double PressureWaveform::aortic_pressure(double t) const { return interpolate(aortic_Pa_, t); }

double PressureWaveform::transvalvular_pressure(double t) const {
  return scale_ * ramp_factor(t) * (ventricular_pressure(t) - aortic_pressure(t));
}

}  // namespace valvefsi
