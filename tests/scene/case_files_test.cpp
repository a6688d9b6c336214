// The TAV case files written by scripts/valve_scene/write_cases.py load with the project's case
// loader, and their waveform tables give the reference's pressures through the project's
// waveform evaluator (docs/valve-scene.md).
#include <cmath>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/case/pressure_waveform.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> scene_cases() {
  std::vector<fs::path> files;
  const std::regex scene_name(R"((fe|fsi)-(ogden|mhgo)-(full|sector)-(coarse|medium|fine)\.textproto)");
  for (const auto& entry : fs::directory_iterator(VALVEFSI_CASES_DIR)) {
    if (std::regex_match(entry.path().filename().string(), scene_name)) files.push_back(entry.path());
  }
  return files;
}

double mmHg(double pascal) { return pascal / valvefsi::kPascalPerMmHg; }

TEST(SceneCaseFiles, AllTwentyFourArePresent) {
  // FE and FSI: 2 materials x 2 variants (full, sector) x 3 resolutions
  EXPECT_EQ(scene_cases().size(), 24U);
}

TEST(SceneCaseFiles, ClosedLoadCasesLoadAndHoldTheLargestReverseDifference) {
  // the closed valve under peak diastolic load (scripts/valve_scene/closed_load.py): from a blood
  // at rest (dp = 0) to the Wiggers cycle's largest reverse difference, 97.2 mmHg at 0.361 s
  const valvefsi::cases::Case cycle = valvefsi::load_case(fs::path(VALVEFSI_CASES_DIR) / "fe-mhgo-sector-coarse.textproto");
  const valvefsi::PressureWaveform cycle_wf(cycle.waveform(), "cycle");
  for (const std::string kind : {"fe", "fsi"}) {
    const fs::path file = fs::path(VALVEFSI_CASES_DIR) / (kind + "-mhgo-sector-coarse-closed-load.textproto");
    SCOPED_TRACE(file.string());
    valvefsi::cases::Case c;
    ASSERT_NO_THROW(c = valvefsi::load_case(file));
    EXPECT_EQ(c.run().fe_only(), kind == "fe");
    EXPECT_DOUBLE_EQ(c.run().end_time(), 0.06);
    const valvefsi::PressureWaveform wf(c.waveform(), file.string());
    EXPECT_NEAR(mmHg(wf.transvalvular_pressure(0.0)), 0.0, 0.01);
    EXPECT_NEAR(mmHg(wf.transvalvular_pressure(0.045)), mmHg(cycle_wf.transvalvular_pressure(0.361)), 0.01);
    EXPECT_LT(mmHg(wf.transvalvular_pressure(0.045)), -90.0);  // reverse: closes the valve
  }
}

TEST(SceneCaseFiles, LoadAndMatchTheirNames) {
  const std::regex parts(R"((fe|fsi)-(ogden|mhgo)-(full|sector)-(coarse|medium|fine)\.textproto)");
  for (const auto& file : scene_cases()) {
    SCOPED_TRACE(file.string());
    valvefsi::cases::Case c;
    ASSERT_NO_THROW(c = valvefsi::load_case(file));
    std::smatch m;
    const std::string name = file.filename().string();
    ASSERT_TRUE(std::regex_match(name, m, parts));
    EXPECT_EQ(c.run().fe_only(), m[1] == "fe");
    EXPECT_DOUBLE_EQ(c.run().end_time(), 1.6);  // two cycles
    EXPECT_EQ(c.solid().material(), m[2] == "ogden" ? valvefsi::cases::SolidCase::OGDEN
                                                    : valvefsi::cases::SolidCase::MHGO);
    EXPECT_EQ(c.solid().mesh_file(), "meshes/valve-" + m[3].str() + "-" + m[4].str() + ".mesh.h5");
    EXPECT_EQ(valvefsi::resolve_case_path(file, c.solid().mesh_file()),
              fs::path(VALVEFSI_CASES_DIR) / "meshes" / ("valve-" + m[3].str() + "-" + m[4].str() + ".mesh.h5"));
    EXPECT_DOUBLE_EQ(c.solid().density(), 1100.0);
    // the rigid stent: its inner face half a leaflet thickness outside the attachment line
    ASSERT_EQ(c.solid().contact_cylinders_size(), 1);
    EXPECT_DOUBLE_EQ(c.solid().contact_cylinders(0).radius(), 11.5e-3 + 0.125e-3);
    EXPECT_EQ(c.solid().contact_cylinders(0).axis(2), 1.0);
    if (m[1] == "fsi") {
      EXPECT_DOUBLE_EQ(c.fluid().density(), 1056.0);
      // the 2D valve's stable setting (docs/thin-leaflet.md): c0 = 20 m/s, CFL 0.1, gauge 0, plates
      // that never pull, smoothed node loads and a 13 us window (mu = 2 for the 0.25 mm leaflet)
      EXPECT_DOUBLE_EQ(c.fluid().sound_speed(), 20.0);
      EXPECT_LE(c.fluid().cfl(), 0.1);
      EXPECT_EQ(c.fluid().background_pressure(), 0.0);
      EXPECT_TRUE(c.fluid().plates_never_pull());
      EXPECT_GT(c.fluid().thin_walls().load_smoothing_radius_ratio(), 0.0);
      const double mu = 2.0 * c.fluid().density() * c.fluid().sound_speed() * c.coupling().window_size() /
                        (c.solid().density() * 0.25e-3);
      EXPECT_GT(mu, 0.0);
      EXPECT_LE(mu, 2.0 + 1e-9);
      // a window of two fluid steps at rest (dt = CFL h / c0) with a margin for the flow's speed,
      // so no window ends in a short third step (docs/fsi-3d.md, "Cost")
      const double h_ratio = c.fluid().has_smoothing_length_ratio() ? c.fluid().smoothing_length_ratio() : 1.3;
      const double step_at_rest = c.fluid().cfl() * h_ratio * c.fluid().particle_spacing() / c.fluid().sound_speed();
      EXPECT_LE(c.coupling().window_size(), 2.0 * step_at_rest * (1.0 + 1e-9)) << name;
      EXPECT_GT(c.coupling().window_size(), 1.5 * step_at_rest) << name;
      // hours-long runs on a shared machine: a live but starved peer must not look frozen
      EXPECT_GE(c.coupling().peer_timeout_s(), 60.0) << name;
      EXPECT_EQ(c.fluid().plates_size(), 2);
      // no step load at t = 0: the plates' offset cancels the waveform (gauge 0 = aortic pressure at opening)
      {
        const valvefsi::PressureWaveform wf(c.waveform(), name);
        EXPECT_NEAR(wf.aortic_pressure(0.0) + c.fluid().plates(1).pressure_mmhg() * valvefsi::kPascalPerMmHg, 0.0, 1.0);
      }
      // a sector's wedge between two mirror planes, its plates a sixth of the tube
      EXPECT_EQ(c.fluid().mirror_planes_size(), m[3] == "sector" ? 2 : 0);
      EXPECT_NEAR(c.fluid().plates(0).area(), M_PI * 0.0184 * 0.0184 / (m[3] == "sector" ? 6.0 : 1.0), 1e-8);
      // the sector fills on the hex-prism lattice whose rows run along both mirror planes (no empty
      // slab along the coaptation plane); the full valve has no planes and keeps the cubic lattice
      if (m[3] == "sector") {
        EXPECT_EQ(c.fluid().fill_lattice(), valvefsi::cases::FluidCase::HEX_PRISM);
        ASSERT_EQ(c.fluid().lattice_axis_size(), 3);
        EXPECT_EQ(c.fluid().lattice_axis(2), 1.0);
        ASSERT_EQ(c.fluid().lattice_row_direction_size(), 3);
        EXPECT_EQ(c.fluid().lattice_row_direction(0), 1.0);
      } else {
        EXPECT_EQ(c.fluid().fill_lattice(), valvefsi::cases::FluidCase::CUBIC);
      }
    }
  }
}

TEST(SceneCaseFiles, TwoDimensionalCasesLoad) {
  // scripts/valve_scene/valve2d.py: FE and FSI x Ogden and MHGO x xcoarse, coarse and medium
  const std::regex name_2d(R"((fe|fsi)-(ogden|mhgo)-2d-(xcoarse|coarse|medium)\.textproto)");
  int found = 0;
  for (const auto& entry : fs::directory_iterator(VALVEFSI_CASES_DIR)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (!std::regex_match(name, m, name_2d)) continue;
    SCOPED_TRACE(name);
    ++found;
    valvefsi::cases::Case c;
    ASSERT_NO_THROW(c = valvefsi::load_case(entry.path()));
    EXPECT_EQ(c.run().dimension(), 2);
    EXPECT_EQ(c.run().fe_only(), m[1] == "fe");
    EXPECT_DOUBLE_EQ(c.run().end_time(), 1.6);
    EXPECT_EQ(c.solid().mesh_file(), "meshes/valve-2d-" + m[3].str() + ".mesh.h5");
    EXPECT_DOUBLE_EQ(c.solid().strip_depth(), 1e-3);
    if (m[1] == "fsi") {
      const auto& f = c.fluid();
      // xcoarse: the 23 mm orifice in 12 spacings
      const double spacing = m[3] == "xcoarse" ? 23e-3 / 12 : (m[3] == "coarse" ? 1e-3 : 0.5e-3);
      EXPECT_NEAR(f.particle_spacing(), spacing, 1e-8 * spacing);  // written to 9 digits
      EXPECT_EQ(f.domain_lower_size(), 2);
      EXPECT_EQ(f.lattice_origin_size(), 2);
      EXPECT_EQ(f.plates_size(), 2);
      EXPECT_EQ(f.plates(0).pressure_source(), valvefsi::cases::FluidPressurePlate::VENTRICULAR);
      EXPECT_EQ(f.plates(1).pressure_source(), valvefsi::cases::FluidPressurePlate::AORTIC);
      // the fluid starts at gauge 0 (docs/fsi-2d.md) and the plates' offset cancels the
      // waveform at t = 0: no step load
      EXPECT_EQ(f.background_pressure(), 0.0);
      const valvefsi::PressureWaveform wf(c.waveform(), name);
      EXPECT_NEAR(wf.aortic_pressure(0.0) + f.plates(1).pressure_mmhg() * valvefsi::kPascalPerMmHg, 0.0, 1.0);
      EXPECT_NEAR(wf.ventricular_pressure(0.0) + f.plates(0).pressure_mmhg() * valvefsi::kPascalPerMmHg, 0.0, 1.0);
      // two taps, each with four more probes across its section (docs/hemodynamics.md), and the
      // flow sections plus the jet core 15 mm downstream
      EXPECT_EQ(f.probes().pressure_points_size(), 2 + 2 * 4);
      EXPECT_GE(f.probes().flow_planes_size(), 4);
      bool jet_core = false;
      for (const auto& plane : f.probes().flow_planes())
        jet_core = jet_core || (plane.name() == "jet_core_15mm" && plane.radius() > 0.0);
      EXPECT_TRUE(jet_core);
      EXPECT_TRUE(f.has_thin_walls());
      // the stable 2D setting of docs/stability-map.md: a window of at most mu = 2 for the
      // 0.25 mm, 1100 kg/m^3 leaflet at c0 = 20 m/s (13 us), the fluid sub-cycling at CFL 0.1
      EXPECT_GT(c.coupling().window_size(), 0.0);
      EXPECT_LE(c.coupling().window_size(), 1.3e-5 * (1.0 + 1e-9));
      EXPECT_LE(f.cfl(), 0.1);
    }
  }
  EXPECT_EQ(found, 12);
}

TEST(SceneCaseFiles, WaveformGivesTheReferencePressures) {
  const auto files = scene_cases();
  ASSERT_FALSE(files.empty());
  const auto c = valvefsi::load_case(files.front());
  ASSERT_EQ(c.waveform().time_s_size(), 800);
  const valvefsi::PressureWaveform wf(c.waveform(), files.front().string());
  EXPECT_DOUBLE_EQ(wf.period(), 0.8);
  EXPECT_LT(mmHg(wf.transvalvular_pressure(-0.001)), 0.0);  // before opening (previous cycle)
  EXPECT_GT(mmHg(wf.transvalvular_pressure(0.002)), 0.0);   // ejection has begun
  EXPECT_NEAR(mmHg(wf.transvalvular_pressure(0.026)), 9.8, 0.2);   // forward peak
  EXPECT_GT(mmHg(wf.transvalvular_pressure(0.230)), 0.0);
  EXPECT_LT(mmHg(wf.transvalvular_pressure(0.245)), 0.0);          // closed by 245 ms
  EXPECT_NEAR(mmHg(wf.transvalvular_pressure(0.361)), -97.2, 0.3);  // diastolic minimum
  EXPECT_NEAR(mmHg(wf.transvalvular_pressure(0.75)), -69.7, 0.3);   // end diastole
  // periodic: the second cycle repeats the first
  EXPECT_DOUBLE_EQ(wf.transvalvular_pressure(0.3615), wf.transvalvular_pressure(1.1615));
}

}  // namespace
