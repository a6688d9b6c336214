#include <gtest/gtest.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/case/pressure_waveform.hpp"

namespace {

using valvefsi::kPascalPerMmHg;
using valvefsi::PressureWaveform;

// Three samples over a 1 s cycle: dp = 10, -20, 0 mmHg at t = 0, 0.5, 0.75.
valvefsi::cases::PressureWaveform three_point_table() {
  valvefsi::cases::PressureWaveform table;
  table.set_period_s(1.0);
  for (const auto& [t, lv, ao] : {std::tuple{0.0, 110.0, 100.0}, std::tuple{0.5, 80.0, 100.0},
                                  std::tuple{0.75, 90.0, 90.0}}) {
    table.add_time_s(t);
    table.add_ventricular_pressure_mmhg(lv);
    table.add_aortic_pressure_mmhg(ao);
  }
  return table;
}

TEST(PressureWaveform, InterpolatesLinearlyInPascal) {
  const PressureWaveform wf(three_point_table());
  EXPECT_NEAR(wf.transvalvular_pressure(0.0), 10 * kPascalPerMmHg, 1e-9);
  EXPECT_NEAR(wf.transvalvular_pressure(0.25), -5 * kPascalPerMmHg, 1e-9);
  EXPECT_NEAR(wf.ventricular_pressure(0.625), 85 * kPascalPerMmHg, 1e-9);
  EXPECT_NEAR(wf.aortic_pressure(0.625), 95 * kPascalPerMmHg, 1e-9);
}

TEST(PressureWaveform, ClosesTheCycleOntoTheFirstSample) {
  const PressureWaveform wf(three_point_table());
  // Between t = 0.75 (dp 0) and t = 1.0 = next cycle's first sample (dp 10).
  EXPECT_NEAR(wf.transvalvular_pressure(0.875), 5 * kPascalPerMmHg, 1e-9);
  EXPECT_NEAR(wf.transvalvular_pressure(3.25), wf.transvalvular_pressure(0.25), 1e-9);
}

TEST(PressureWaveform, ScaleAndRampApply) {
  auto table = three_point_table();
  table.set_scale(2.0);
  table.set_ramp_time(0.2);
  const PressureWaveform wf(table);
  EXPECT_NEAR(wf.transvalvular_pressure(0.0), 0.0, 1e-12);
  // Half-way through a cosine ramp the factor is one half.
  const double unramped = 2.0 * (wf.ventricular_pressure(0.1) - wf.aortic_pressure(0.1));
  EXPECT_NEAR(wf.transvalvular_pressure(0.1), 0.5 * unramped, 1e-9);
  EXPECT_NEAR(wf.transvalvular_pressure(0.5), -40 * kPascalPerMmHg, 1e-9);
}

TEST(PressureWaveform, RejectsUnsortedTimesNamingTheIndex) {
  auto table = three_point_table();
  table.set_time_s(2, 0.4);
  try {
    PressureWaveform wf(table, "w.textproto");
    FAIL() << "expected CaseError";
  } catch (const valvefsi::CaseError& error) {
    EXPECT_NE(std::string(error.what()).find("w.textproto: field 'waveform.time_s[2]' = 0.4"),
              std::string::npos)
        << error.what();
  }
}

TEST(PressureWaveform, RejectsMismatchedLengths) {
  auto table = three_point_table();
  table.add_aortic_pressure_mmhg(1.0);
  EXPECT_THROW(PressureWaveform{table}, valvefsi::CaseError);
}

}  // namespace
