// Experiment program for the 3D thin-wall scenes on FluidSolver<3> with ThinWallModel3D: runs
// one scene and writes its time series (force on the surface, counters, cost per step) as CSV
// for docs/thin-leaflet.md; --no-surface runs the same particles without the surface (cost
// reference).
#include <CLI/CLI.hpp>
#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/fluid/case_setup.hpp"
#include "valvefsi/fluid/thin_wall/scenes_3d.hpp"
#include "valvefsi/fluid/thin_wall/solver_run_3d.hpp"

using namespace valvefsi::fluid;
using namespace valvefsi::fluid::thin_wall;

namespace {

// A surface as plain text (scripts/dump_surface.py): "N", N lines "x y z t", "M", M lines "a b c".
ImmersedSurfaceGeometry<3> read_surface(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open " + file);
  ImmersedSurfaceGeometry<3> g;
  g.nodes_per_cell = 3;
  std::size_t n = 0, m = 0;
  in >> n;
  g.nodes.resize(n);
  g.node_thickness.resize(n);
  for (std::size_t k = 0; k < n; ++k) in >> g.nodes[k][0] >> g.nodes[k][1] >> g.nodes[k][2] >> g.node_thickness[k];
  in >> m;
  g.cells.resize(3 * m);
  for (auto& c : g.cells) in >> c;
  if (!in) throw std::runtime_error("bad surface file " + file);
  return g;
}

// Diagnostics: every fluid particle (near the surface or not) with its kernel sum C and grad C
// (the case must switch shifting on), distance and side from the surface, and whether its
// closest point is on the free boundary.
void write_particle_dump(const std::string& file, const FluidSolver<3>& solver, const ThinWallModel3D& model) {
  const auto& p = solver.particles();
  std::ofstream out(file);
  out << "x,y,z,C,gx,gy,gz,near,d,side,boundary,vx,vy,vz,p\n";
  const bool with_c = p.kernel_sum.size() == p.size();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    const Vec3 x{p.position[0][i], p.position[1][i], p.position[2][i]};
    const auto c = closest_point(model.mesh(), x);
    out << x[0] << ',' << x[1] << ',' << x[2] << ',' << (with_c ? p.kernel_sum[i] : 0.f) << ','
        << (with_c ? p.kernel_sum_gradient[0][i] : 0.f) << ',' << (with_c ? p.kernel_sum_gradient[1][i] : 0.f) << ','
        << (with_c ? p.kernel_sum_gradient[2][i] : 0.f) << ',' << (model.near_surface(i) ? 1 : 0) << ',' << c.distance << ','
        << c.side << ',' << (c.on_boundary ? 1 : 0) << ',' << p.velocity[0][i] << ',' << p.velocity[1][i] << ','
        << p.velocity[2][i] << ',' << p.pressure[i] - solver.settings().background_pressure << '\n';
  }
}

// The fluid part of a case (e.g. the coupled sector) at rest with the solid's surface at
// rest in it, for a number of steps: loads at rest, leaks and the cost per step, with and
// without the surface.
int run_case_at_rest(const std::string& case_file, const std::string& surface_file, long steps, bool no_surface, bool aligned, bool behind_only,
                     int relax_cycles, long relax_steps, double smoothing_ratio) {
  const valvefsi::cases::Case c = valvefsi::load_case(case_file);
  auto setup = fluid_setup_from_case<3>(c, case_file);
  FluidSolver<3> solver = make_solver<3>(std::move(setup));
  const ThinWallModel3D* model = nullptr;
  if (!no_surface) {
    ThinWall3DSettings settings;
    settings.wall_acceleration_in_pressure = c.fluid().thin_walls().wall_acceleration_in_pressure();
    settings.particle_aligned_layers = aligned;
    settings.lattice_in_front = !behind_only;
    settings.load_smoothing_radius_ratio =
        smoothing_ratio >= 0 ? smoothing_ratio : c.fluid().thin_walls().load_smoothing_radius_ratio();
    FluidSettings<3> fluid = solver.settings();
    if (std::getenv("THIN_WALL_NO_IMAGES")) fluid.mirror_planes.clear();  // diagnostics: the leaflet without its images
    auto m = std::make_unique<ThinWallModel3D>(read_surface(surface_file), fluid, settings);
    model = m.get();
    solver.set_immersed_surface(std::move(m));
    // Start-up relaxation (experiment): cycles of relax_steps steps at rest, after each of
    // which every fluid particle keeps its position but loses its velocity and gets its initial
    // density back, so that the particles next to the leaflet settle where the background
    // pressure balances.
    std::vector<float> initial;
    {
      const auto& p = solver.particles();
      for (std::size_t i = 0; i < p.size(); ++i)
        if (p.kind[i] == Kind::fluid) {
          if (initial.size() <= p.id[i]) initial.resize(p.id[i] + 1, 0.0f);
          initial[p.id[i]] = p.density_excess[i];
        }
    }
    for (int cycle = 0; cycle < relax_cycles; ++cycle) {
      for (long k = 0; k < relax_steps; ++k) solver.step();
      const auto& p = solver.particles();
      // relax_steps = 0: move every fluid particle down the kernel sum's gradient instead
      // (needs the case's shifting on for the solver to keep grad C), by 0.25 dp^2 grad C capped
      // at 0.05 dp, never across or close to the leaflet: the background pressure's force on a
      // particle is -2 p_b grad C / rho, so this settles the particles where it vanishes.
      const bool by_gradient = relax_steps == 0 && p.kernel_sum_gradient[0].size() == p.size();
      const double dp = solver.settings().particle_spacing;
      double largest_shift = 0;
      Particles<3> q;
      double v2 = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        const Kind kind = p.kind[i];
        if (kind != Kind::fluid && kind != Kind::wall) continue;
        std::array<float, 3> v{p.velocity[0][i], p.velocity[1][i], p.velocity[2][i]};
        float rho = p.density_excess[i];
        Vec3 x{p.position[0][i], p.position[1][i], p.position[2][i]};
        if (kind == Kind::fluid) {
          v2 = std::max(v2, static_cast<double>(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
          v = {0.0f, 0.0f, 0.0f};
          rho = initial[p.id[i]];
          if (by_gradient) {
            Vec<3> shift;
            double length = 0;
            for (int d = 0; d < 3; ++d) {
              shift[d] = -0.25 * dp * dp * p.kernel_sum_gradient[d][i];
              length += shift[d] * shift[d];
            }
            length = std::sqrt(length);
            if (length > 0.05 * dp)
              for (int d = 0; d < 3; ++d) shift[d] *= 0.05 * dp / length;
            // Never towards a mirror plane within 0.4 dp (the fill's margin): a particle there
            // sits almost on its own image.
            bool off_planes = true;
            for (const auto& plane : solver.settings().mirror_planes) {
              double before = 0, after = 0;
              for (int d = 0; d < 3; ++d) {
                before += (x[d] - plane.point[d]) * plane.normal[d];
                after += (x[d] + shift[d] - plane.point[d]) * plane.normal[d];
              }
              off_planes = off_planes && !(after < 0.4 * dp && after < before);
            }
            if (off_planes && solver.immersed_surface()->accept_shift(p, i, shift)) {
              for (int d = 0; d < 3; ++d) x[d] += shift[d];
              largest_shift = std::max(largest_shift, std::min(length, 0.05 * dp));
            }
          }
        }
        q.add(x, v, rho, kind, p.body[i]);
        q.id.back() = p.id[i];
      }
      const Vec3 f = model->total_force();
      std::printf("relaxation cycle %d: largest speed %.4g m/s, largest shift %.3g dp, net force %.4g %.4g %.4g N before the reset\n",
                  cycle + 1, std::sqrt(v2), largest_shift / dp, f[0], f[1], f[2]);
      auto fresh = std::make_unique<ThinWallModel3D>(read_surface(surface_file), fluid, settings);
      model = fresh.get();
      solver = FluidSolver<3>(solver.settings(), std::move(q), solver.plates(), std::move(fresh));
    }
  }
  if (model && solver.particles().kernel_sum.size() == solver.particles().size()) {
    // Kernel completeness next to the leaflet at the start (the case must switch shifting on
    // for the solver to keep the kernel sums): mean and lowest per side.
    const auto& p = solver.particles();
    double sum[2] = {0, 0}, low[2] = {9, 9};
    std::size_t count[2] = {0, 0};
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid || !model->near_surface(i)) continue;
      const auto c = closest_point(model->mesh(), {p.position[0][i], p.position[1][i], p.position[2][i]});
      const int k = c.side > 0 ? 1 : 0;
      sum[k] += p.kernel_sum[i];
      low[k] = std::min(low[k], static_cast<double>(p.kernel_sum[i]));
      ++count[k];
    }
    for (int k = 0; k < 2; ++k)
      std::printf("side %+d: %zu near particles, kernel sum mean %.4f, lowest %.4f\n", k ? 1 : -1, count[k],
                  count[k] ? sum[k] / static_cast<double>(count[k]) : 0.0, low[k]);
    if (const char* dump = std::getenv("THIN_WALL_PARTICLE_DUMP")) write_particle_dump(dump, solver, *model);
  }
  const auto t0 = std::chrono::steady_clock::now();
  // THIN_WALL_PRINT_EVERY=N: every N steps the time, the net force on the surface, its mean
  // node load over the node areas and the largest fluid speed (the at-rest history).
  const long every = std::getenv("THIN_WALL_PRINT_EVERY") ? std::atol(std::getenv("THIN_WALL_PRINT_EVERY")) : 0;
  for (long k = 0; k < steps; ++k) {
    solver.step();
    if (every > 0 && (k + 1) % every == 0) {
      const auto& p = solver.particles();
      double v2 = 0;
      for (std::size_t i = 0; i < p.size(); ++i)
        if (p.kind[i] == Kind::fluid)
          v2 = std::max(v2, static_cast<double>(p.velocity[0][i] * p.velocity[0][i] + p.velocity[1][i] * p.velocity[1][i] +
                                                p.velocity[2][i] * p.velocity[2][i]));
      double load = 0, area = 0, largest = 0, largest_raw = 0, raw_load = 0;
      Vec3 f{0, 0, 0};
      if (model) {
        std::vector<Vec<3>> forces(model->node_count());
        model->node_forces(forces);
        const auto& raw = model->raw_node_forces();
        for (std::size_t j = 0; j < forces.size(); ++j) {
          const double fj = std::sqrt(forces[j][0] * forces[j][0] + forces[j][1] * forces[j][1] + forces[j][2] * forces[j][2]);
          const double rj = j < raw.size() ? std::sqrt(raw[j][0] * raw[j][0] + raw[j][1] * raw[j][1] + raw[j][2] * raw[j][2]) : 0.0;
          load += fj;
          raw_load += rj;
          largest = std::max(largest, fj / model->node_areas()[j]);
          largest_raw = std::max(largest_raw, rj / model->node_areas()[j]);
          area += model->node_areas()[j];
          for (int d = 0; d < 3; ++d) f[d] += forces[j][d];
        }
      }
      std::printf("step %ld t %.4e s: net force %.4g %.4g %.4g N, mean node load %.4g Pa (raw %.4g), largest %.4g Pa (raw %.4g), "
                  "net/area %.4g Pa, max speed %.4g m/s, leaks %zu\n",
                  k + 1, solver.time(), f[0], f[1], f[2], area > 0 ? load / area : 0.0, area > 0 ? raw_load / area : 0.0, largest,
                  largest_raw, area > 0 ? std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) / area : 0.0, std::sqrt(v2),
                  model ? model->counters().leaks : std::size_t{0});
      std::fflush(stdout);
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%s: %zu particles, %ld steps to t = %.3g s, %.2f s, %.2f ms/step\n", no_surface ? "no surface" : "with surface",
              solver.particles().size(), steps, solver.time(), wall, 1e3 * wall / static_cast<double>(steps));
  if (model) {
    if (const char* dump = std::getenv("THIN_WALL_PARTICLE_DUMP_END")) write_particle_dump(dump, solver, *model);
    const auto k = model->counters();
    const Vec3 f = model->total_force();
    double largest = 0;
    std::vector<Vec<3>> forces(model->node_count());
    model->node_forces(forces);
    double largest_pressure = 0, mean_pressure = 0, area = 0;
    for (std::size_t j = 0; j < forces.size(); ++j) {
      const auto& x = forces[j];
      const double f = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
      largest = std::max(largest, f);
      largest_pressure = std::max(largest_pressure, f / model->node_areas()[j]);
      mean_pressure += f;
      area += model->node_areas()[j];
    }
    std::printf("node loads over node areas: largest %.4g Pa, mean %.4g Pa (leaflet area %.4g m^2)\n", largest_pressure,
                mean_pressure / area, area);
    if (const char* dump = std::getenv("THIN_WALL_NODE_DUMP")) {
      std::ofstream out(dump);
      out << "x,y,z,fx,fy,fz,area,p0,p1,w0,w1,fx_raw,fy_raw,fz_raw\n";
      const auto& m = model->mesh();
      for (std::size_t j = 0; j < forces.size(); ++j) {
        const auto& st = model->node_states()[j];
        out << m.position[j][0] << ',' << m.position[j][1] << ',' << m.position[j][2] << ',' << forces[j][0] << ','
            << forces[j][1] << ',' << forces[j][2] << ',' << model->node_areas()[j] << ',' << st.side[0].pressure << ','
            << st.side[1].pressure << ',' << st.side[0].weight << ',' << st.side[1].weight << ',' << model->raw_node_forces()[j][0]
            << ',' << model->raw_node_forces()[j][1] << ',' << model->raw_node_forces()[j][2] << '\n';
      }
    }
    std::printf("surface: %zu particles near it; total force %.4g %.4g %.4g N, largest node force %.3g N; corrections %zu leaks %zu "
                "rejected shifts %zu; lost %zu\n",
                model->near_count(), f[0], f[1], f[2], largest, k.corrections, k.leaks, k.rejected_shifts, solver.lost_count());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"3D thin-wall scenes: two_levels, gap, disk, flap"};
  std::string scene = "two_levels", output;
  double dp = 0.025, end_time = 0.5, gap = 0.1, width = 0.15, sample_interval = 1e-3, lattice_ratio = 1.0, window = 1e-3;
  bool mirror = false, no_surface = false;
  OscillatingDisk disk;
  RockingFlap flap;
  app.add_option("--scene", scene, "two_levels | gap | disk | flap")->check(CLI::IsMember({"two_levels", "gap", "disk", "flap"}));
  app.add_option("--dp", dp, "particle spacing (m)");
  app.add_option("--end", end_time, "end time (s)");
  app.add_option("--gap", gap, "gap under the membrane (m), scene gap");
  app.add_option("--width", width, "tank width (m), scenes two_levels and gap");
  app.add_flag("--mirror", mirror, "two_levels/gap: mirror planes instead of side walls");
  app.add_option("--lattice-ratio", lattice_ratio, "virtual lattice spacing / dp");
  app.add_option("--window", window, "motion window (s)");
  app.add_option("--radius", disk.radius, "disk radius a (m)");
  app.add_option("--amplitude", disk.amplitude, "disk amplitude A (m)");
  app.add_option("--period", disk.period, "disk period (s)");
  app.add_option("--box", disk.box, "disk box side (m)");
  app.add_flag("--quarter", disk.quarter, "disk: the quarter y, z >= 0 with mirror planes y = 0 and z = 0 (force x4)");
  app.add_flag("--no-surface", no_surface, "run the same particles without the surface (cost reference)");
  app.add_option("--sample", sample_interval, "output interval (s)");
  app.add_option("--output", output, "CSV file of the time series");
  std::string case_file, surface_file;
  long steps = 100;
  app.add_option("--case", case_file, "a 3D case file: run its fluid at rest with --surface in it (no scene)");
  app.add_option("--surface", surface_file, "surface as text (scripts/dump_surface.py), with --case");
  app.add_option("--steps", steps, "steps, with --case");
  bool aligned = false, behind_only = false;
  int relax_cycles = 0;
  long relax_steps = 20;
  double smoothing_ratio = -1.0;
  app.add_option("--relax-cycles", relax_cycles, "with --case: start-up relaxation cycles (velocities and densities reset after each)");
  app.add_option("--relax-steps", relax_steps, "with --case: steps per relaxation cycle");
  app.add_flag("--behind-only", behind_only, "virtual lattice behind the tangent plane only");
  app.add_option("--load-smoothing", smoothing_ratio, "with --case: node-load smoothing radius / dp (default: the case's)");
  app.add_flag("--aligned-layers", aligned, "virtual layers continue the particle's own lattice through the wall");
  bool no_lattice_beyond_edge = false;
  bool round_edge_state = false;
  app.add_flag("--no-lattice-beyond-edge", no_lattice_beyond_edge, "no virtual lattice for particles beyond the free edge");
  app.add_flag("--round-edge-state", round_edge_state,
               "virtual points reached round a free edge carry the other side's pressure and fluid velocity");
  CLI11_PARSE(app, argc, argv);
  if (!case_file.empty()) return run_case_at_rest(case_file, surface_file, steps, no_surface, aligned, behind_only, relax_cycles, relax_steps,
                                                   smoothing_ratio);

  ThinWallCase3D c = scene == "two_levels" ? two_level_tank_3d(dp, 0.5, 0.25, width, 0.0, mirror)
                     : scene == "gap"      ? two_level_tank_3d(dp, 0.5, 0.25, width, gap, mirror)
                     : scene == "disk"     ? oscillating_disk_box(dp, disk)
                                           : rocking_flap_box(dp, flap);
  c.wall_settings.virtual_spacing_ratio = lattice_ratio;
  c.wall_settings.particle_aligned_layers = aligned;
  c.wall_settings.lattice_in_front = !behind_only;
  c.wall_settings.lattice_beyond_free_edge = !no_lattice_beyond_edge;
  c.wall_settings.fluid_state_round_free_edge = round_edge_state;
  std::ofstream csv;
  if (!output.empty()) {
    csv.open(output);
    csv << "time,fx,fy,fz,X,V,corrections,leaks,rejected_shifts,lost,near,steps,wall_s\n";
  }
  if (no_surface) {
    FluidSolver<3> solver(c.fluid, fill_particles<3>(c.scene, c.fluid));
    const auto t0 = std::chrono::steady_clock::now();
    solver.advance_to(end_time);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("no surface: %zu particles, %ld steps, %.2f s, %.3f ms/step\n", solver.particles().size(), solver.step_count(), wall,
                1e3 * wall / static_cast<double>(solver.step_count()));
    return 0;
  }
  ThinWallSolverRun3D flow(std::move(c), window);
  const double omega = 2.0 * std::numbers::pi / disk.period;
  const auto t0 = std::chrono::steady_clock::now();
  double next = 0.0;
  while (flow.time() < end_time * (1.0 - 1e-12)) {
    flow.step();
    if (flow.time() >= next - 1e-12) {
      next += sample_interval;
      const Vec3 f = flow.wall_force();
      const auto k = flow.model().counters();
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double t = flow.time();
      if (csv)
        csv << t << ',' << f[0] << ',' << f[1] << ',' << f[2] << ',' << -disk.amplitude * std::cos(omega * t) << ','
            << disk.amplitude * omega * std::sin(omega * t) << ',' << k.corrections << ',' << k.leaks << ',' << k.rejected_shifts
            << ',' << flow.solver().lost_count() << ',' << flow.model().near_count() << ',' << flow.step_count() << ',' << wall
            << '\n';
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto k = flow.model().counters();
  const Vec3 f = flow.wall_force();
  std::printf("%s: %zu particles (%zu near the surface), %ld steps, %.2f s, %.3f ms/step; force %.4g %.4g %.4g N; "
              "corrections %zu leaks %zu rejected shifts %zu lost %zu\n",
              scene.c_str(), flow.particles().size(), flow.model().near_count(), flow.step_count(), wall,
              1e3 * wall / static_cast<double>(flow.step_count()), f[0], f[1], f[2], k.corrections, k.leaks, k.rejected_shifts,
              flow.solver().lost_count());
  return 0;
}
