#pragma once
// The two mappings whose H is sparse by construction: one or a cell's worth of entries per row.

#include "valvefsi/coupling/interface_mapping.hpp"

namespace valvefsi::coupling::detail {

// Each point takes the value of its nearest node: one entry 1 per row.
Eigen::SparseMatrix<double, Eigen::RowMajor> nearest_neighbor_matrix(const InterfaceMesh& surface,
                                                                      const Eigen::Matrix3Xd& points);

// Each point takes the barycentric interpolation at its closest point on the surface's cells.
Eigen::SparseMatrix<double, Eigen::RowMajor> nearest_projection_matrix(const InterfaceMesh& surface,
                                                                        const Eigen::Matrix3Xd& points);

// Partition-of-unity RBF: local Wendland C2 systems of about nodes_per_cluster nodes, blended.
Eigen::SparseMatrix<double, Eigen::RowMajor> partition_of_unity_rbf_matrix(const Eigen::Matrix3Xd& nodes,
                                                                            const Eigen::Matrix3Xd& points,
                                                                            double support_radius,
                                                                            bool linear_polynomial,
                                                                            int nodes_per_cluster);

}  // namespace valvefsi::coupling::detail
