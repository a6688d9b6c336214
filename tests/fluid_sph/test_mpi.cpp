// The fluid split over MPI ranks (slabs along the last axis) must give the results of one rank
// to round-off: run under `mpiexec -n 2`, every rank first runs the whole case alone (the
// reference), then the same case split over the ranks; rank 0 gathers the split run's
// particles by id and compares. Cases: the 2D still water column (gravity, walls, pressure
// probe, tank load) and the coarse 3D tube between two pressure plates (plates moving along
// the slab axis, so plate walls migrate between ranks; flow and pressure probes).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/case_setup.hpp"
#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/probes.hpp"

namespace valvefsi::fluid {
namespace {

int world_rank() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

// Own particles of every rank on rank 0, by id: position and velocity (2 D values).
template <int D>
std::map<std::uint32_t, std::array<double, 2 * D>> gather_by_id(const FluidSolver<D>& solver) {
  const auto& p = solver.particles();
  const auto [first, last] = solver.owned_range();
  std::vector<double> mine;
  for (std::size_t i = first; i < last; ++i) {
    if (p.kind[i] != Kind::fluid && p.kind[i] != Kind::wall) continue;
    mine.push_back(p.id[i]);
    for (int d = 0; d < D; ++d) mine.push_back(p.position[d][i]);
    for (int d = 0; d < D; ++d) mine.push_back(p.velocity[d][i]);
  }
  const std::vector<double> all = solver.decomposition() != nullptr ? solver.decomposition()->gather(mine) : mine;
  std::map<std::uint32_t, std::array<double, 2 * D>> by_id;
  for (std::size_t k = 0; k + 2 * D < all.size() + 1; k += 2 * D + 1) {
    std::array<double, 2 * D> values{};
    for (int j = 0; j < 2 * D; ++j) values[static_cast<std::size_t>(j)] = all[k + 1 + static_cast<std::size_t>(j)];
    EXPECT_TRUE(by_id.emplace(static_cast<std::uint32_t>(all[k]), values).second) << "particle " << all[k] << " owned twice";
  }
  return by_id;
}

// Largest position and velocity differences between the runs (rank 0), and their scales.
template <int D>
void expect_same_particles(const FluidSolver<D>& single, const FluidSolver<D>& split, double position_tolerance,
                           double velocity_tolerance) {
  const auto a = gather_by_id(single);  // on one rank: its own particles are all of them
  const auto b = gather_by_id(split);
  if (world_rank() != 0) return;
  ASSERT_EQ(a.size(), b.size());
  double dx = 0, dv = 0, vmax = 0;
  for (const auto& [id, va] : a) {
    const auto it = b.find(id);
    ASSERT_NE(it, b.end()) << "particle " << id << " missing in the split run";
    for (int d = 0; d < D; ++d) {
      dx = std::max(dx, std::abs(va[static_cast<std::size_t>(d)] - it->second[static_cast<std::size_t>(d)]));
      dv = std::max(dv, std::abs(va[static_cast<std::size_t>(D + d)] - it->second[static_cast<std::size_t>(D + d)]));
      vmax = std::max(vmax, std::abs(va[static_cast<std::size_t>(D + d)]));
    }
  }
  std::printf("%zu particles: largest position difference %.3e m, velocity difference %.3e m/s (largest speed %.3e m/s)\n",
              a.size(), dx, dv, vmax);
  EXPECT_LT(dx, position_tolerance);
  EXPECT_LT(dv, velocity_tolerance);
}

// Which rank owns each particle (rank 0: all ids; the others: empty).
template <int D>
std::map<std::uint32_t, int> owners(const FluidSolver<D>& split) {
  const auto& p = split.particles();
  const auto [first, last] = split.owned_range();
  std::vector<double> mine;
  for (std::size_t i = first; i < last; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    mine.push_back(p.id[i]);
    mine.push_back(world_rank());
  }
  const std::vector<double> all = split.decomposition() != nullptr ? split.decomposition()->gather(mine) : mine;
  std::map<std::uint32_t, int> owner;
  for (std::size_t k = 0; k + 1 < all.size(); k += 2) owner[static_cast<std::uint32_t>(all[k])] = static_cast<int>(all[k + 1]);
  return owner;
}

FluidSettings<2> tank_settings() {
  FluidSettings<2> s;
  s.particle_spacing = 0.025;
  s.rest_density = 1000.0;
  s.dynamic_viscosity = 1e-3;
  s.artificial_viscosity = 0.02;
  s.gravity = {0.0, -9.81};
  s.sound_speed = 20.0 * std::sqrt(9.81 * 0.5);
  s.domain_lower = {-0.2, -0.2};
  s.domain_upper = {1.2, 1.0};
  return s;
}

// The still column: hydrostatic pressure and the tank's load, split.
TEST(FluidMpi, StillWaterColumnOnTwoRanksEqualsOneRank) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const FluidSettings<2> s = tank_settings();
  SceneGeometry<2> scene;
  scene.walls.push_back(container_box<2>({0.0, 0.0}, {1.0, 1e9}));
  scene.fluid.push_back({{0.0, 0.0}, {1.0, 0.5}, {}, {}});
  FluidSolver<2> single(s, fill_particles(scene, s));
  FluidSolver<2> split(s, fill_particles(scene, s));
  split.decompose(MPI_COMM_WORLD);
  ASSERT_EQ(split.decomposition() != nullptr, ranks > 1);
  single.request_body_forces();
  split.request_body_forces();
  single.advance_to(0.2);
  split.advance_to(0.2);
  EXPECT_EQ(single.step_count(), split.step_count());
  EXPECT_EQ(single.time(), split.time());
  expect_same_particles(single, split, 1e-9, 1e-6);
  const double p_single = pressure_at<2>(single, {0.5, 0.1}), p_split = pressure_at<2>(split, {0.5, 0.1});
  const double load_single = single.body_forces()[0][1], load_split = split.body_forces()[0][1];
  if (world_rank() == 0) {
    std::printf("bottom pressure %.9g / %.9g Pa (rho g (H - y) = %.6g), tank load %.9g / %.9g N/m (1 / %d ranks)\n", p_single,
                p_split, 1000 * 9.81 * 0.4, load_single, load_split, ranks);
    EXPECT_NEAR(p_split, p_single, 1e-6 * std::abs(p_single));
    EXPECT_NEAR(load_split, load_single, 1e-6 * std::abs(load_single));
    EXPECT_EQ(split.lost_count(), single.lost_count());
  }
}

// A collapsing column (0.3 x 0.6 m): particles fall across the cut between the slabs and
// migrate; the order of floating-point sums then differs, so the runs agree to round-off
// grown over the flow, not bit for bit.
TEST(FluidMpi, CollapsingColumnMigratesAndStaysWithinRoundOff) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const FluidSettings<2> s = tank_settings();
  SceneGeometry<2> scene;
  scene.walls.push_back(container_box<2>({0.0, 0.0}, {1.0, 1e9}));
  scene.fluid.push_back({{0.0, 0.0}, {0.3, 0.6}, {}, {}});
  FluidSolver<2> single(s, fill_particles(scene, s));
  FluidSolver<2> split(s, fill_particles(scene, s));
  split.decompose(MPI_COMM_WORLD);
  const auto before = owners(split);
  single.advance_to(0.25);
  split.advance_to(0.25);
  const auto after = owners(split);
  EXPECT_EQ(single.step_count(), split.step_count());
  expect_same_particles(single, split, 1e-6, 1e-4);
  if (world_rank() == 0) {
    int migrated = 0;
    for (const auto& [id, rank] : after) migrated += before.at(id) != rank;
    std::printf("%d of %zu fluid particles changed rank\n", migrated, after.size());
    if (ranks > 1) {
      EXPECT_GT(migrated, 20);
    }
  }
}

TEST(FluidMpi, TubeWithPlatesOnTwoRanksEqualsOneRank) {
  const auto dir = std::filesystem::temp_directory_path() / ("vfsi-fluid-mpi-" + std::to_string(world_rank()));
  std::filesystem::create_directories(dir);
  const auto case_file = dir / "tube.textproto";
  std::ofstream(case_file) << R"(run { end_time: 0.01 dimension: 3 }
waveform {
  period_s: 0.8
  time_s: [0.0, 0.05, 0.1]
  ventricular_pressure_mmHg: [80.0, 110.0, 120.0]
  aortic_pressure_mmHg: [80.0, 100.0, 115.0]
  ramp_time: 0.002
}
fluid {
  particle_spacing: 0.004
  sound_speed: 40
  background_pressure: 10665.8
  domain_lower: [-0.03, -0.03, -0.01]
  domain_upper: [0.03, 0.03, 0.13]
  walls { tube { origin: [0, 0, -0.01] axis: [0, 0, 1] length: 0.14 radius: 0.0184 } }
  fluid_blocks { box { lower: [-0.02, -0.02, 0.008] upper: [0.02, 0.02, 0.112] } }
  plates {
    shape { annular_disk { origin: [0, 0, 0] axis: [0, 0, 1] thickness: 0.008 outer_radius: 0.0184 } }
    normal: [0, 0, 1]  area: 0.0010636  pressure_source: VENTRICULAR  pressure_mmHg: -80
  }
  plates {
    shape { annular_disk { origin: [0, 0, 0.112] axis: [0, 0, 1] thickness: 0.008 outer_radius: 0.0184 } }
    normal: [0, 0, -1]  area: 0.0010636  pressure_source: AORTIC  pressure_mmHg: -70
  }
}
)";
  const auto c = valvefsi::load_case(case_file.string());
  FluidSolver<3> single = make_solver<3>(fluid_setup_from_case<3>(c, case_file));
  FluidSolver<3> split = make_solver<3>(fluid_setup_from_case<3>(c, case_file));
  split.decompose(MPI_COMM_WORLD);
  for (int k = 0; k < 60; ++k) {
    single.step();
    split.step();
  }
  EXPECT_EQ(single.time(), split.time());
  expect_same_particles(single, split, 1e-9, 1e-6);
  ProbePlane<3> mid{{0, 0, 0.06}, {0, 0, 1}, 0.0};
  const double q_single = flow_rate<3>(single, mid), q_split = flow_rate<3>(split, mid);
  const double p_single = pressure_at<3>(single, {0, 0, 0.03}), p_split = pressure_at<3>(split, {0, 0, 0.03});
  if (world_rank() == 0) {
    for (std::size_t k = 0; k < 2; ++k) {
      const auto& a = single.plates()[k];
      const auto& b = split.plates()[k];
      std::printf("plate %zu: displacement %.9e / %.9e m, force %.9g / %.9g N\n", k, a.displacement, b.displacement,
                  a.fluid_force[2], b.fluid_force[2]);
      EXPECT_NEAR(b.displacement, a.displacement, 1e-6 * std::abs(a.displacement) + 1e-12);
      EXPECT_NEAR(b.fluid_force[2], a.fluid_force[2], 1e-5 * std::abs(a.fluid_force[2]));
    }
    std::printf("flow %.9e / %.9e m^3/s, upstream pressure %.9g / %.9g Pa\n", q_single, q_split, p_single, p_split);
    EXPECT_NEAR(q_split, q_single, 1e-5 * std::abs(q_single) + 1e-12);
    EXPECT_NEAR(p_split, p_single, 1e-5 * std::abs(p_single) + 1e-6);
    EXPECT_GT(std::abs(single.plates()[0].displacement), 1e-7);  // the plates moved: particles migrated
  }
}

}  // namespace
}  // namespace valvefsi::fluid

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {  // one report, from rank 0
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  const int failed = RUN_ALL_TESTS();
  int any = failed;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return any;
}
