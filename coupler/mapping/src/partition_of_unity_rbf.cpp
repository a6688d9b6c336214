#include "point_cloud_tree.hpp"
#include "radial_basis_system.hpp"
#include "rbf_polynomial.hpp"
#include "sparse_mappings.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

// Partition-of-unity RBF: the interface is covered by overlapping balls ("clusters"); each
// has its own small RBF interpolant (the same Wendland C2 kernel and linear polynomial as the
// global system, solved densely), and a point blends the clusters that contain it with
// normalised Wendland weights w_c(y) = phi(|y - centre_c| / rho). Each local row sums to one
// and reproduces linear fields, so the blend does too; H is sparse and explicit.

namespace valvefsi::coupling::detail {

namespace {

struct Cluster {
  Eigen::Vector3d centre;
  double radius;
};

// Local interpolation matrix (points x nodes) of the RBF system on the cluster's nodes.
Eigen::MatrixXd local_rbf_matrix(const Eigen::Matrix3Xd& nodes, const Eigen::Matrix3Xd& points, double support_radius,
                                 bool linear_polynomial) {
  const Eigen::Index n = nodes.cols();
  const auto kernel = [&](const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
    Eigen::MatrixXd k(a.cols(), b.cols());
    for (Eigen::Index j = 0; j < b.cols(); ++j) {
      for (Eigen::Index i = 0; i < a.cols(); ++i) k(i, j) = wendland_c2((a.col(i) - b.col(j)).norm() / support_radius);
    }
    return k;
  };
  const Eigen::LLT<Eigen::MatrixXd> phi(kernel(nodes, nodes));
  const RbfPolynomial polynomial = RbfPolynomial::fit(nodes, linear_polynomial);
  const Eigen::MatrixXd p = polynomial.at(nodes);
  const Eigen::MatrixXd q = phi.solve(p);
  const Eigen::LLT<Eigen::MatrixXd> schur(p.transpose() * q);
  if (phi.info() != Eigen::Success || schur.info() != Eigen::Success) {
    throw std::runtime_error("radial-basis mapping (partition of unity): a local system of " + std::to_string(n) +
                             " nodes could not be factorised; check for duplicate nodes");
  }
  // H_c = E_phi Phi^-1 (I - P S^-1 Q^T) + E_p S^-1 Q^T, formed densely (n is small).
  const Eigen::MatrixXd s_inverse_qt = schur.solve(q.transpose());
  const Eigen::MatrixXd phi_inverse = phi.solve(Eigen::MatrixXd::Identity(n, n));
  return kernel(points, nodes) * (phi_inverse - q * s_inverse_qt) + polynomial.at(points) * s_inverse_qt;
}

}  // namespace

Eigen::SparseMatrix<double, Eigen::RowMajor> partition_of_unity_rbf_matrix(const Eigen::Matrix3Xd& nodes,
                                                                            const Eigen::Matrix3Xd& points,
                                                                            double support_radius,
                                                                            bool linear_polynomial,
                                                                            int nodes_per_cluster) {
  const PointCloudTree node_tree(nodes);
  const Eigen::Index n = nodes.cols();
  const int wanted = static_cast<int>(std::min<Eigen::Index>(std::max(nodes_per_cluster, 4), n));

  // Cluster radius: the median distance to the wanted-th nearest node, over a sample of nodes.
  std::vector<double> reach;
  for (Eigen::Index i = 0; i < n; i += std::max<Eigen::Index>(1, n / 200)) {
    std::vector<std::uint32_t> index(static_cast<std::size_t>(wanted));
    std::vector<double> distance_squared(static_cast<std::size_t>(wanted));
    node_tree.nearest_k(nodes.col(i), wanted, index, distance_squared);
    reach.push_back(std::sqrt(distance_squared.back()));
  }
  std::nth_element(reach.begin(), reach.begin() + static_cast<std::ptrdiff_t>(reach.size() / 2), reach.end());
  const double radius = std::max(reach[reach.size() / 2], 1e-300);

  // Centres: a greedy cover of the nodes, each node within 0.7 radius of a centre (so it sits
  // well inside a cluster); nodes in tree order keep it spatially coherent.
  std::vector<Cluster> clusters;
  std::vector<char> covered(static_cast<std::size_t>(n), 0);
  std::vector<std::pair<std::uint32_t, double>> found;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (covered[static_cast<std::size_t>(i)]) continue;
    clusters.push_back({nodes.col(i), radius});
    node_tree.within(nodes.col(i), 0.7 * radius, found);
    for (const auto& [j, d2] : found) covered[j] = 1;
    covered[static_cast<std::size_t>(i)] = 1;
  }
  // Points outside every cluster (far off the surface) get their own, around the nearest node.
  Eigen::Matrix3Xd centres(3, static_cast<Eigen::Index>(clusters.size()));
  for (std::size_t k = 0; k < clusters.size(); ++k) centres.col(static_cast<Eigen::Index>(k)) = clusters[k].centre;
  const PointCloudTree centre_tree(centres);  // keeps a reference: centres must outlive it
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (centre_tree.nearest(points.col(i)).second < 0.81 * radius * radius) continue;  // weight > phi(0.9)
    const auto [node, d2] = node_tree.nearest(points.col(i));
    clusters.push_back({nodes.col(node), std::max(radius, 2.0 * std::sqrt(d2))});
  }

  // A cluster must see as many polynomial directions as the whole interface: a small patch of a
  // curved surface can be exactly flat (a strip between two generators of a cylinder), and would
  // then blend a wrong normal gradient into its neighbours. Grow such clusters.
  const Eigen::Index global_terms = RbfPolynomial::fit(nodes, linear_polynomial).terms();
  for (Cluster& cluster : clusters) {
    for (int growth = 0; growth < 12; ++growth) {
      node_tree.within(cluster.centre, cluster.radius, found);
      Eigen::Matrix3Xd local(3, static_cast<Eigen::Index>(found.size()));
      for (std::size_t k = 0; k < found.size(); ++k) local.col(static_cast<Eigen::Index>(k)) = nodes.col(found[k].first);
      if (RbfPolynomial::fit(local, linear_polynomial).terms() >= global_terms) break;
      cluster.radius *= 1.25;
    }
  }

  // Point-to-cluster membership with weights, then the normalised blend.
  const PointCloudTree point_tree(points);
  std::vector<std::vector<std::pair<Eigen::Index, double>>> members(clusters.size());  // (point, weight)
  Eigen::VectorXd weight_sum = Eigen::VectorXd::Zero(points.cols());
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    point_tree.within(clusters[c].centre, clusters[c].radius, found);
    for (const auto& [i, d2] : found) {
      const double w = wendland_c2(std::sqrt(d2) / clusters[c].radius);
      if (w <= 0.0) continue;
      members[c].emplace_back(static_cast<Eigen::Index>(i), w);
      weight_sum(static_cast<Eigen::Index>(i)) += w;
    }
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    if (members[c].empty()) continue;
    node_tree.within(clusters[c].centre, clusters[c].radius, found);
    Eigen::Matrix3Xd local_nodes(3, static_cast<Eigen::Index>(found.size()));
    for (std::size_t k = 0; k < found.size(); ++k) local_nodes.col(static_cast<Eigen::Index>(k)) = nodes.col(found[k].first);
    Eigen::Matrix3Xd local_points(3, static_cast<Eigen::Index>(members[c].size()));
    for (std::size_t k = 0; k < members[c].size(); ++k) {
      local_points.col(static_cast<Eigen::Index>(k)) = points.col(members[c][k].first);
    }
    const Eigen::MatrixXd local = local_rbf_matrix(local_nodes, local_points, support_radius, linear_polynomial);
    for (std::size_t k = 0; k < members[c].size(); ++k) {
      const auto [point, w] = members[c][k];
      const double blend = w / weight_sum(point);
      for (std::size_t j = 0; j < found.size(); ++j) {
        entries.emplace_back(point, found[j].first, blend * local(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)));
      }
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> h(points.cols(), n);
  h.setFromTriplets(entries.begin(), entries.end());
  return h;
}

}  // namespace valvefsi::coupling::detail
