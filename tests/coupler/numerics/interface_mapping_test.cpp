// Mapping: exactness (constants for all, linear fields for projection and RBF), conservation of
// total force and power, NN identity, robustness off the surface, and clear errors.
#include "surface_fixtures.hpp"
#include "valvefsi/coupling/interface_mapping.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace valvefsi::coupling {
namespace {

using testing::LinearField;

MappingOptions options_for(MappingMethod method, double support_radius = 0.0, int nodes_per_cluster = 0) {
  MappingOptions options;
  options.method = method;
  options.rbf_support_radius = support_radius;
  options.rbf_nodes_per_cluster = nodes_per_cluster;
  return options;
}

Eigen::Matrix3Xd random_field(Eigen::Index columns, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Matrix3Xd f(3, columns);
  for (Eigen::Index j = 0; j < columns; ++j) f.col(j) << normal(random), normal(random), normal(random);
  return f;
}

double max_abs(const Eigen::Matrix3Xd& x) { return x.cwiseAbs().maxCoeff(); }

struct Case {
  std::string name;
  MappingMethod method;
  double support_radius;
  int nodes_per_cluster = 0;
  MappingOptions options() const { return options_for(method, support_radius, nodes_per_cluster); }
};

class EveryMethod : public ::testing::TestWithParam<Case> {};

TEST_P(EveryMethod, RowsSumToOneAndConstantsAreExact) {
  const auto mesh = testing::curved_patch();
  const auto points = testing::points_on_cells(mesh, 400, 1);
  const auto mapping = InterfaceMapping::build(mesh, points, GetParam().options());
  ASSERT_EQ(mapping.point_count(), 400);
  ASSERT_EQ(mapping.node_count(), mesh.positions.cols());
  const Eigen::VectorXd row_sums = mapping.matrix() * Eigen::VectorXd::Ones(mapping.node_count());
  EXPECT_LT((row_sums.array() - 1.0).abs().maxCoeff(), 1e-12);
  const Eigen::Vector3d constant(0.25, -1.5, 3.0);
  const Eigen::Matrix3Xd at_nodes = constant.replicate(1, mesh.positions.cols());
  const Eigen::Matrix3Xd mapped = mapping.map_consistent(at_nodes);
  EXPECT_LT(max_abs(mapped.colwise() - constant), 1e-12 * constant.norm());
}

TEST_P(EveryMethod, ConservativeMappingKeepsTotalForceAndPower) {
  const auto mesh = testing::curved_patch();
  const auto points = testing::points_on_cells(mesh, 500, 2);
  const auto mapping = InterfaceMapping::build(mesh, points, GetParam().options());
  const Eigen::Matrix3Xd forces_at_points = random_field(points.cols(), 3);
  const Eigen::Matrix3Xd forces_at_nodes = mapping.map_conservative(forces_at_points);
  const Eigen::Vector3d total_points = forces_at_points.rowwise().sum();
  const Eigen::Vector3d total_nodes = forces_at_nodes.rowwise().sum();
  const double scale = forces_at_points.cwiseAbs().sum();
  EXPECT_LT((total_nodes - total_points).norm(), 1e-13 * scale);

  // Power: f_nodes . v_nodes == f_points . (H v_nodes) for any velocities.
  const Eigen::Matrix3Xd velocities_at_nodes = random_field(mesh.positions.cols(), 4);
  const double power_nodes = (forces_at_nodes.array() * velocities_at_nodes.array()).sum();
  const double power_points = (forces_at_points.array() * mapping.map_consistent(velocities_at_nodes).array()).sum();
  EXPECT_NEAR(power_nodes, power_points, 1e-12 * scale * max_abs(velocities_at_nodes));
}

TEST_P(EveryMethod, MapFunctionsApplyTheMatrixAndItsTranspose) {
  const auto mesh = testing::tilted_plate();
  const auto points = testing::points_on_cells(mesh, 150, 5);
  const auto mapping = InterfaceMapping::build(mesh, points, GetParam().options());
  const Eigen::Matrix3Xd u = random_field(mesh.positions.cols(), 6);
  const Eigen::Matrix3Xd f = random_field(points.cols(), 7);
  const Eigen::MatrixXd h = Eigen::MatrixXd(mapping.matrix());
  EXPECT_LT(max_abs(mapping.map_consistent(u) - (h * u.transpose()).transpose()), 1e-11);
  EXPECT_LT(max_abs(mapping.map_conservative(f) - (h.transpose() * f.transpose()).transpose()), 1e-11);
}

INSTANTIATE_TEST_SUITE_P(Mapping, EveryMethod,
                         ::testing::Values(Case{"nearest_neighbor", MappingMethod::nearest_neighbor, 0.0},
                                           Case{"nearest_projection", MappingMethod::nearest_projection, 0.0},
                                           Case{"rbf", MappingMethod::radial_basis, 0.004},
                                           Case{"rbf_partition_of_unity", MappingMethod::radial_basis, 0.004, 25}),
                         [](const auto& info) { return info.param.name; });

TEST(NearestProjection, ReproducesLinearFieldsOnACurvedSurface) {
  const auto mesh = testing::curved_patch();
  const auto points = testing::points_on_cells(mesh, 800, 11);
  const LinearField field = testing::some_linear_field();
  const auto mapping = InterfaceMapping::build(mesh, points, options_for(MappingMethod::nearest_projection));
  const Eigen::Matrix3Xd exact = field(points);
  EXPECT_LT(max_abs(mapping.map_consistent(field(mesh.positions)) - exact), 1e-12 * max_abs(exact));
}

TEST(NearestProjection, ReproducesLinearFieldsOnA2dPolyline) {
  const auto mesh = testing::arc_2d();
  const auto points = testing::points_on_cells(mesh, 200, 12);
  const LinearField field = testing::some_linear_field();
  const auto mapping = InterfaceMapping::build(mesh, points, options_for(MappingMethod::nearest_projection));
  const Eigen::Matrix3Xd exact = field(points);
  EXPECT_LT(max_abs(mapping.map_consistent(field(mesh.positions)) - exact), 1e-12 * max_abs(exact));
}

TEST(NearestProjection, PointsSlightlyOffTheSurfaceTakeTheirFootPoint) {
  // A flat plate: moving a point along the normal must not change its weights.
  const auto mesh = testing::tilted_plate();
  const auto on_surface = testing::points_on_cells(mesh, 300, 13);
  const Eigen::Vector3d e0 = mesh.positions.col(1) - mesh.positions.col(0);
  const Eigen::Vector3d e1 = mesh.positions.col(11) - mesh.positions.col(0);
  const Eigen::Vector3d normal = e0.cross(e1).normalized();
  Eigen::Matrix3Xd off_surface = on_surface;
  for (Eigen::Index i = 0; i < off_surface.cols(); ++i) off_surface.col(i) += (i % 2 ? 1.0 : -1.0) * 2e-4 * normal;
  const auto on = InterfaceMapping::build(mesh, on_surface, options_for(MappingMethod::nearest_projection));
  const auto off = InterfaceMapping::build(mesh, off_surface, options_for(MappingMethod::nearest_projection));
  EXPECT_LT(Eigen::MatrixXd(on.matrix() - off.matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(NearestProjection, FindsTheClosestCellOnAnUnevenMeshAsBruteForceDoes) {
  // Strongly graded cells (one big triangle fan beside tiny ones) and points scattered off the
  // surface: the mapped position (H x_nodes) must be the closest surface point found by brute force.
  auto mesh = testing::grid_surface(12, 4, [](double u, double v) {
    const double x = 0.02 * u * u * u;  // cells from 5 um to 3.5 mm wide
    return Eigen::Vector3d(x, 0.006 * v, 0.002 * std::sin(3.0 * v + 40.0 * x));
  });
  std::mt19937 random(14);
  std::uniform_real_distribution<double> x(-0.002, 0.022), y(-0.001, 0.007), z(-0.003, 0.005);
  Eigen::Matrix3Xd points(3, 150);
  for (Eigen::Index i = 0; i < points.cols(); ++i) points.col(i) << x(random), y(random), z(random);
  const auto mapping = InterfaceMapping::build(mesh, points, options_for(MappingMethod::nearest_projection));
  const Eigen::Matrix3Xd foot = mapping.map_consistent(mesh.positions);
  // Brute force over every cell: dense sampling would be inexact, so use the distance bound of
  // the closest point instead: no cell may contain a point closer than the mapped foot point.
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const double mapped_distance = (foot.col(i) - points.col(i)).norm();
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index c = 0; c < mesh.cells.cols(); ++c) {
      InterfaceMesh one = mesh;
      one.cells = mesh.cells.col(c);
      const auto single = InterfaceMapping::build(one, points.col(i), options_for(MappingMethod::nearest_projection));
      best = std::min(best, (single.map_consistent(mesh.positions).col(0) - points.col(i)).norm());
    }
    ASSERT_NEAR(mapped_distance, best, 1e-12) << "point " << i;
  }
}

class RadialBasis : public ::testing::TestWithParam<int> {};  // nodes per cluster, 0 = global

TEST_P(RadialBasis, ReproducesLinearFieldsOnAndNearACurvedSurface) {
  const auto mesh = testing::curved_patch();
  Eigen::Matrix3Xd points = testing::points_on_cells(mesh, 500, 21);
  points.rightCols(100).array() *= 1.02;  // some points 0.24 mm outside the cylinder
  points.col(0) *= 1.5;                   // and one 6 mm off, outside every cluster
  const LinearField field = testing::some_linear_field();
  const auto mapping = InterfaceMapping::build(mesh, points, options_for(MappingMethod::radial_basis, 0.004, GetParam()));
  const Eigen::Matrix3Xd exact = field(points);
  const Eigen::Matrix3Xd error = mapping.map_consistent(field(mesh.positions)) - exact;
  EXPECT_LT(max_abs(error), 1e-10 * max_abs(exact));
}

TEST_P(RadialBasis, ReproducesLinearFieldsOnATiltedPlateAndA2dArc) {
  const LinearField field = testing::some_linear_field();
  for (const auto& mesh : {testing::tilted_plate(), testing::arc_2d()}) {
    const auto points = testing::points_on_cells(mesh, 300, 22);
    const auto mapping =
        InterfaceMapping::build(mesh, points, options_for(MappingMethod::radial_basis, 0.003, GetParam()));
    const Eigen::Matrix3Xd exact = field(points);
    EXPECT_LT(max_abs(mapping.map_consistent(field(mesh.positions)) - exact), 1e-10 * max_abs(exact));
  }
}

INSTANTIATE_TEST_SUITE_P(Mapping, RadialBasis, ::testing::Values(0, 12, 40), [](const auto& info) {
  return info.param == 0 ? std::string("global") : "partition_of_unity_" + std::to_string(info.param);
});

TEST(RadialBasis, WithoutTheLinearTermsConstantsStayExactAndLinearFieldsDoNot) {
  const auto mesh = testing::curved_patch();
  const auto points = testing::points_on_cells(mesh, 300, 23);
  MappingOptions options = options_for(MappingMethod::radial_basis, 0.004);
  options.rbf_linear_polynomial = false;
  const auto mapping = InterfaceMapping::build(mesh, points, options);
  const Eigen::VectorXd row_sums = mapping.matrix() * Eigen::VectorXd::Ones(mapping.node_count());
  EXPECT_LT((row_sums.array() - 1.0).abs().maxCoeff(), 1e-12);
  const LinearField field = testing::some_linear_field();
  const Eigen::Matrix3Xd exact = field(points);
  EXPECT_GT(max_abs(mapping.map_consistent(field(mesh.positions)) - exact), 1e-6 * max_abs(exact));
}

TEST(NearestNeighbor, OnCoincidentPointSetsIsThePermutation) {
  const auto mesh = testing::curved_patch();
  std::vector<Eigen::Index> order(static_cast<std::size_t>(mesh.positions.cols()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::shuffle(order.begin(), order.end(), std::mt19937(31));
  Eigen::Matrix3Xd points(3, mesh.positions.cols());
  for (std::size_t i = 0; i < order.size(); ++i) points.col(static_cast<Eigen::Index>(i)) = mesh.positions.col(order[i]);
  const auto mapping = InterfaceMapping::build(mesh, points, options_for(MappingMethod::nearest_neighbor));
  const Eigen::Matrix3Xd u = random_field(mesh.positions.cols(), 32);
  const Eigen::Matrix3Xd mapped = mapping.map_consistent(u);
  for (std::size_t i = 0; i < order.size(); ++i) {
    ASSERT_EQ(mapped.col(static_cast<Eigen::Index>(i)), u.col(order[i]));
  }
  const auto identity = InterfaceMapping::build(mesh, mesh.positions, options_for(MappingMethod::nearest_neighbor));
  EXPECT_EQ(identity.map_consistent(u), u);
  EXPECT_EQ(identity.map_conservative(u), u);
}

TEST(MappingParse, NamesAndUnknownNames) {
  EXPECT_EQ(parse_mapping_method("nearest-neighbor"), MappingMethod::nearest_neighbor);
  EXPECT_EQ(parse_mapping_method("nearest-projection"), MappingMethod::nearest_projection);
  EXPECT_EQ(parse_mapping_method("rbf"), MappingMethod::radial_basis);
  try {
    parse_mapping_method("linear");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'linear'"), std::string::npos) << message;
    EXPECT_NE(message.find("nearest-projection"), std::string::npos) << message;
    EXPECT_NE(message.find("rbf"), std::string::npos) << message;
  }
}

void expect_error(const InterfaceMesh& mesh, const Eigen::Matrix3Xd& points, const MappingOptions& options,
                  const std::string& expected_field) {
  try {
    (void)InterfaceMapping::build(mesh, points, options);
    FAIL() << "no exception for " << expected_field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(expected_field), std::string::npos) << e.what();
  }
}

TEST(MappingErrors, BadInputNamesTheFieldAndWhatIsAllowed) {
  const auto mesh = testing::curved_patch(4, 3);
  const auto points = testing::points_on_cells(mesh, 10, 41);
  const auto projection = options_for(MappingMethod::nearest_projection);

  expect_error(InterfaceMesh{}, points, projection, "solid_surface.positions");
  expect_error(mesh, Eigen::Matrix3Xd(3, 0), projection, "fluid_points");

  auto wrong_rows = mesh;
  wrong_rows.nodes_per_cell = 2;
  expect_error(wrong_rows, points, projection, "solid_surface.cells");

  auto out_of_range = mesh;
  out_of_range.cells(2, 5) = static_cast<int>(mesh.positions.cols());
  expect_error(out_of_range, points, projection, "solid_surface.cells(2, 5)");

  auto bad_areas = mesh;
  bad_areas.node_areas.resize(3);
  expect_error(bad_areas, points, projection, "solid_surface.node_areas");

  auto no_cells = mesh;
  no_cells.cells.resize(3, 0);
  expect_error(no_cells, points, projection, "solid_surface.cells");

  auto bad_cell_size = mesh;
  bad_cell_size.nodes_per_cell = 4;
  expect_error(bad_cell_size, points, projection, "solid_surface.nodes_per_cell");

  Eigen::Matrix3Xd nan_points = points;
  nan_points(1, 7) = std::nan("");
  expect_error(mesh, nan_points, projection, "fluid_points");

  expect_error(mesh, points, options_for(MappingMethod::radial_basis, 0.0), "rbf_support_radius");
  expect_error(mesh, points, options_for(MappingMethod::radial_basis, 0.004, -5), "rbf_nodes_per_cluster");

  const auto mapping = InterfaceMapping::build(mesh, points, projection);
  EXPECT_THROW((void)mapping.map_consistent(Eigen::Matrix3Xd(3, 2)), std::invalid_argument);
  EXPECT_THROW((void)mapping.map_conservative(Eigen::Matrix3Xd(3, 2)), std::invalid_argument);
}

}  // namespace
}  // namespace valvefsi::coupling
