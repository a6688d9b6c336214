#pragma once
// The cardiac pressure waveform of a case: ventricular and aortic pressure tabulated over one
// cycle, repeated periodically, interpolated linearly. Drives the valve in every mode: the
// fluid's pressure plates and the FE-only uniform leaflet load use the same curve.

#include <string>
#include <vector>

#include "case.pb.h"

namespace valvefsi {

inline constexpr double kPascalPerMmHg = 133.322387415;

class PressureWaveform {
 public:
  // Checks the table (equal lengths, >= 2 samples, strictly increasing times within
  // [0, period)); throws CaseError naming `source_name` and the offending field and index.
  explicit PressureWaveform(const cases::PressureWaveform& table,
                            const std::string& source_name = "case");

  // Pressures in Pa at simulated time t (s); t may exceed the period (cycles repeat).
  [[nodiscard]] double ventricular_pressure(double t) const;
  [[nodiscard]] double aortic_pressure(double t) const;
  // Ventricular minus aortic (Pa): positive pushes the valve open. Scaled by `scale` and
  // ramped in smoothly over `ramp_time` from t = 0.
  [[nodiscard]] double transvalvular_pressure(double t) const;

  [[nodiscard]] double period() const { return period_; }

 private:
  [[nodiscard]] double interpolate(const std::vector<double>& values_Pa, double t) const;
  [[nodiscard]] double ramp_factor(double t) const;

  double period_;
  double scale_;
  double ramp_time_;
  std::vector<double> time_;
  std::vector<double> ventricular_Pa_;
  std::vector<double> aortic_Pa_;
};

}  // namespace valvefsi
