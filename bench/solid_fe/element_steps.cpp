// Diagnostic for issue 3's speed question (docs/solid_fe.md, "Speed, fourth session"): which
// elements set the stable step of a saved state, and what the step would be if the few most
// critical ones were sub-cycled. Reads a case (its mesh and material) and one snapshot of a run's
// solid_fields.h5, prints the smallest element step bounds, and the global step with the k
// smallest elements taken out (their nodes integrated with a fraction of it).
//   solid_element_steps --case C --fields RUN/solid_fields.h5 --snapshot 250 [--count 12]
#include <algorithm>
#include <cstdio>
#include <numeric>
#include <set>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <hdf5.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/solid/case_setup.hpp"
#include "valvefsi/solid/shell_forces.hpp"
#include "valvefsi/solid/shell_solver.hpp"

int main(int argc, char** argv) {
  using namespace valvefsi::solid;
  CLI::App app{"stable-step bound per element of a saved state"};
  std::string case_file, fields;
  int snapshot = 0, count = 12;
  app.add_option("--case", case_file)->required();
  app.add_option("--fields", fields)->required();
  app.add_option("--snapshot", snapshot)->required();
  app.add_option("--count", count);
  CLI11_PARSE(app, argc, argv);
  const auto c = valvefsi::load_case(case_file);
  SolidSetup setup = setup_from_case(c, case_file);
  const ShellSolver& solver = setup.shell_solver();
  const ShellModel& model = solver.model();
  const Eigen::Index n = model.reference_positions.cols();

  Eigen::Matrix3Xd x(3, n);
  double time = 0;
  {
    const hid_t f = H5Fopen(fields.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const std::string group = fmt::format("/snapshots/{:06d}", snapshot);
    const hid_t d = H5Dopen2(f, (group + "/position").c_str(), H5P_DEFAULT);
    if (f < 0 || d < 0) {
      std::fprintf(stderr, "%s: no %s/position\n", fields.c_str(), group.c_str());
      return 2;
    }
    H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x.data());
    H5Dclose(d);
    const hid_t g = H5Gopen2(f, group.c_str(), H5P_DEFAULT);
    const hid_t a = H5Aopen(g, "time", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, &time);
    H5Aclose(a);
    H5Gclose(g);
    H5Fclose(f);
  }
  const auto elements = static_cast<std::int64_t>(model.elements.size());
  std::vector<HingeSide> sides(static_cast<std::size_t>(3 * elements));
  for (std::int64_t e = 0; e < elements; ++e) own_hinge_sides(model, e, x, sides.data());
  std::vector<double> step(static_cast<std::size_t>(elements));
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, n);
  std::visit(
      [&](const auto& law) {
        for (std::int64_t e = 0; e < elements; ++e) {
          step[static_cast<std::size_t>(e)] =
              add_element_internal_force(model, model.elements[static_cast<std::size_t>(e)], law, x, forces, true,
                                         sides.data(), e)
                  .stable_step;
        }
      },
      solver.material());
  std::vector<std::int64_t> order(step.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return step[static_cast<std::size_t>(a)] < step[static_cast<std::size_t>(b)]; });
  std::printf("t = %.4f s: element step bounds (no safety), smallest first\n", time);
  std::set<std::int64_t> nodes;
  for (int k = 0; k < std::min<int>(count, static_cast<int>(order.size())); ++k) {
    const auto e = order[static_cast<std::size_t>(k)];
    const auto& el = model.elements[static_cast<std::size_t>(e)];
    for (const auto a : el.nodes) nodes.insert(a);
    const double next = step[static_cast<std::size_t>(order[static_cast<std::size_t>(k + 1)])];
    std::printf("  #%d element %lld: %.3g us; without the %d smallest the bound is %.3g us (x%.2f), their nodes: %zu\n",
                k + 1, static_cast<long long>(e), 1e6 * step[static_cast<std::size_t>(e)], k + 1, 1e6 * next,
                next / step[static_cast<std::size_t>(order[0])], nodes.size());
  }
  return 0;
}
