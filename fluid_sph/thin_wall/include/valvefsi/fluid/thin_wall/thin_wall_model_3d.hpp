#pragma once
// The two-sided thin wall in 3D behind FluidSolver<3>'s immersed-surface hook: the leaflets'
// mid-surface triangles the coupler sends (one mesh, possibly several disjoint leaflets) with
// the 2D model's method carried to triangles (docs/thin-leaflet.md, "3D"):
//   classify          - per particle within a support: candidate triangles (bucket grid),
//                       closest point and side (pseudo-normals), leak audit by particle id
//   blocked           - a pair whose segment crosses the mesh does not interact
//   update_surface_states - per node and side: Adami et al. (2012, eq. 27) from that side's
//                       fluid only (the nodes are the markers; area = a third of each
//                       incident triangle)
//   add_surface_rates - closest-point virtual lattice behind the wall, in the particle's
//                       shadow, carrying that side's state; action = reaction onto the nodes
//                       with the barycentric weights of the wall point seen; gauge loads
//   correct_crossings - swept test against the moving triangles, put back on the start side
//   accept_shift      - shifting never crosses or comes within the clearance
// Fluid mirror planes (sector cases): the mesh is extended by its mirror image in every plane
// and, where the planes cross, under every other element of the group they generate (the
// fluid's images of images, mirror_group.hpp), so pairs between a particle and an image, the
// lattice behind the leaflet near a plane and the side of image particles all see the image
// leaflet; a load seen on an image triangle is mapped back onto the real nodes (the image
// fluid's share of the real leaflet's load).
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "thin_wall_case.pb.h"
#include "valvefsi/fluid/fluid_settings.hpp"
#include "valvefsi/fluid/immersed_surface.hpp"
#include "valvefsi/fluid/mirror_group.hpp"
#include "valvefsi/fluid/thin_wall/load_smoothing.hpp"
#include "valvefsi/fluid/thin_wall/ordered_node_loads.hpp"
#include "valvefsi/fluid/thin_wall/triangle_mesh.hpp"
#include "valvefsi/fluid/thin_wall/window_motion.hpp"

namespace valvefsi::fluid::thin_wall {

struct ThinWall3DSettings {
  // Spacing of the virtual lattice over dp. 1 in 3D (the 2D default 0.5 costs 8x the points:
  // ~300 per near-wall particle; in 2D the two spacings gave 1.55 and 1.60 on the plate).
  double virtual_spacing_ratio = 1.0;
  // Closest distance (over dp) a put-back or shifted particle keeps from the mid-surface
  // (raised to half the leaflet's thickness where that is more).
  double clearance_ratio = 0.1;
  // Virtual layers at depths k delta - d (d: the particle's distance from the wall), i.e. the
  // particle's own lattice continued through the wall, instead of (k - 1/2) delta. Both agree
  // for d = delta / 2; where the leaflet cuts the fluid lattice elsewhere the fixed depths leave
  // a gap or an overlap next to the wall that the background pressure turns into a start-up
  // push (docs/thin-leaflet.md, "3D", loads at rest in the sector).
  bool particle_aligned_layers = false;
  // The lattice fills the whole ball round the particle (layers in front of the tangent plane
  // too), so that the shadow of a concave leaflet is filled where it bulges towards the
  // particle; false: behind the tangent plane only.
  bool lattice_in_front = false;
  // Extrapolate the wall pressure with the wall's acceleration (eq. 27); off in coupled runs.
  bool wall_acceleration_in_pressure = true;
  // Radius (over dp, along the mesh) over which each node's load is spread before it goes to
  // the solid, conserving total force and moment (load_smoothing.hpp); 0: the raw loads.
  double load_smoothing_radius_ratio = 0.0;
  // Experiment on the free edge's bias (docs/thin-leaflet.md, "Session 8"): false leaves out the
  // virtual lattice of a particle whose closest point is on the free edge (beyond it), where the
  // fluid hidden behind the leaflet really flows round the edge instead of moving with it.
  bool lattice_beyond_free_edge = true;
  // Experiment on the same bias: a virtual point the particle reaches round a free edge within
  // the support (|x_a - e| + |e - x_v| < R for a point e of the edge) carries the other side's
  // pressure and moves with that side's fluid velocity (no mirror), in the momentum and the
  // continuity equations (the 2D plate's --round-edge --round-edge-velocity).
  bool fluid_state_round_free_edge = false;
  // The lattice's shadow test skips, per layer, the candidates a point's segment cannot meet:
  // those wholly on the particle's side and those whose central projection from the particle
  // onto the layer (a bounding rectangle, with a margin far above round-off) misses the point.
  // Exact: the same first hit for every point. false tests every candidate (for the tests).
  bool lattice_shadow_bounds = true;
};

// Consistent orientation of an open triangle mesh: flips triangles (per connected piece, from
// its lowest-numbered triangle) so that neighbours traverse their shared edge in opposite
// directions. Throws std::invalid_argument for an edge shared by more than two triangles or a
// non-orientable piece. Returns how many triangles were flipped.
std::size_t orient_consistently(std::vector<std::array<std::uint32_t, 3>>& triangles);

class ThinWallModel3D final : public ImmersedSurfaceModel<3> {
 public:
  ThinWallModel3D(const ImmersedSurfaceGeometry<3>& geometry, const FluidSettings<3>& fluid, ThinWall3DSettings settings);

  void set_window_target(double end_time, std::span<const Vec<3>> end_positions,
                         std::span<const Vec<3>> end_velocities) override;
  void move_to(double time) override;
  double max_node_speed() const override;

  void begin_step(const Particles<3>& particles) override;
  void correct_crossings(Particles<3>& particles) override;
  void classify(const Particles<3>& particles) override;
  bool near_surface(std::size_t i) const override { return i < dyn_.near.size() && dyn_.near[i].near; }
  bool blocked(std::uint32_t a, std::uint32_t b, const Particles<3>& particles) const override;
  void update_surface_states(const Particles<3>& particles, const CellGrid<3>& grid) override;
  void add_surface_rates(Particles<3>& particles) override;
  bool accept_shift(const Particles<3>& particles, std::size_t i, const Vec<3>& shift) override;

  std::size_t node_count() const override { return node_count_; }
  void node_forces(std::span<Vec<3>> forces) const override;
  ImmersedSurfaceCounters counters() const override { return dyn_.counters; }

  void save_checkpoint() override;
  void restore_checkpoint() override;

  // Restart files: the window's motion, the nodes' states and loads, the counters, the side
  // memory by particle id and the last classify's per-particle data in the particle order of
  // the moment (arrays named "motion.*", "nodes.*", "by_id.*", "particles.*", "counters").
  std::optional<std::vector<NamedArray>> restart_state() const override;
  void load_restart_state(std::span<const NamedArray> arrays) override;

  // Diagnostics and tests.
  struct SideState {
    double pressure = 0.0;    // Pa (with the background pressure, as the fluid's)
    Vec3 velocity{};          // Shepard average of that side's fluid velocity
    double weight = 0.0;      // Shepard sum (0: no fluid on that side)
  };
  struct NodeState {
    std::array<SideState, 2> side;  // index 0: side -1, 1: side +1
  };
  const TriangleMesh& mesh() const { return mesh_; }  // with the mirror images
  std::size_t real_triangle_count() const { return real_triangles_; }
  const std::vector<NodeState>& node_states() const { return dyn_.state; }
  const std::vector<double>& node_areas() const { return area_; }
  Vec3 total_force() const;  // sum of the node forces
  // The loads as the fluid's virtual points left them on the nodes (node_forces: smoothed).
  const std::vector<Vec3>& raw_node_forces() const { return dyn_.force; }
  const NodeLoadSmoother& load_smoother() const { return smoother_; }
  std::size_t near_count() const;
  double time() const { return dyn_.motion.current_time(); }

 private:
  struct NearWall {
    ClosestPoint3 closest;
    bool near = false;
  };
  // Everything that changes during a run (saved and restored as a whole: the solver restores
  // its particle order without re-classifying, so the per-particle data must come back too).
  struct Dynamic {
    explicit Dynamic(WindowMotionT<3> m) : motion(std::move(m)) {}
    WindowMotionT<3> motion;
    std::vector<Vec3> x, v, a;  // real nodes at the last move_to
    std::vector<NodeState> state;
    std::vector<Vec3> force;    // per real node
    std::vector<NearWall> near;
    std::vector<std::vector<std::uint32_t>> candidates;
    std::vector<std::vector<double>> candidate_distance;  // per particle: its candidates' distances (ascending)
    // Per particle, cached at the classify for the pair blocking: its signed distance from each
    // candidate's plane, and where it was then (the cache holds while it has not moved).
    std::vector<std::vector<double>> candidate_side;
    std::vector<Vec3> classified_position;
    std::vector<std::int8_t> side_by_id;
    std::vector<std::uint8_t> corrected_by_id;
    std::vector<Vec3> previous_by_id;
    std::vector<Vec3> start_position;
    std::vector<Vec3> start_nodes;  // all mesh nodes (with images) at begin_step
    ImmersedSurfaceCounters counters;
  };

  void place_mesh();  // mesh_ (with images) from dyn_.x, v, a
  // Particle i's candidates' distances, or nullptr when they are not known (after a restart
  // until the next classify): callers then test every candidate.
  const std::vector<double>* distances_of(std::size_t i) const {
    const auto& d = dyn_.candidate_distance;
    return i < d.size() && d[i].size() == dyn_.candidates[i].size() ? &d[i] : nullptr;
  }
  // Particle i's plane sides per candidate when x is still where the classify saw it, else
  // nullptr (then recomputed: the same expression, the same answer).
  const double* sides_of(std::size_t i, const Vec3& x) const {
    const auto& c = dyn_.candidate_side;
    return i < c.size() && c[i].size() == dyn_.candidates[i].size() && dyn_.classified_position[i] == x ? c[i].data() : nullptr;
  }
  // Slack on a distance bound for rounding (the triangle test's touching tolerance is 1e-12 of
  // a triangle): far below any distance the model resolves.
  double reach_margin() const { return 1e-6 * fluid_.particle_spacing; }
  // Real node of mesh node k.
  std::uint32_t real_node(std::uint32_t k) const { return origin_node_[k]; }
  // A real vector seen at the image under map m (-1: none), and back.
  Vec3 to_image(int map, const Vec3& v) const;
  Vec3 to_real(int map, const Vec3& v) const;

  FluidSettings<3> fluid_;
  ThinWall3DSettings settings_;
  std::size_t node_count_ = 0;
  std::size_t real_triangles_ = 0;
  std::vector<MirrorPlane<3>> planes_;
  std::vector<std::uint32_t> origin_node_;  // per mesh node: its real node
  std::vector<MirrorMap<3>> maps_;          // each plane's reflection, then the compound images
  std::vector<int> node_map_;               // per mesh node: the map it is the image under (-1: real)
  std::vector<int> triangle_map_;           // per mesh triangle: the map (-1: real)
  std::vector<int> sheet_of_triangle_;      // per mesh triangle: its connected piece (a node id)
  std::vector<double> area_;                // per real node (m^2)
  double clearance_ = 0.0;
  TriangleMesh mesh_;
  std::vector<Vec3> mesh_velocity_, mesh_acceleration_;
  std::vector<Vec3> face_normal_;    // unit, per mesh triangle
  std::vector<double> face_offset_;  // normal . first corner
  std::vector<std::array<Vec3, 2>> face_box_;  // bounding box per mesh triangle
  TriangleBuckets buckets_;
  bool buckets_current_ = false;  // built for the mesh as it is placed now
  std::uint64_t generation_ = 0;  // of the per-particle data (new at each classify or restore): keys the blocking's per-thread caches
  NodeLoadSmoother smoother_;
  Dynamic dyn_;
  OrderedNodeLoads<3> node_loads_;  // scratch of add_surface_rates
  std::optional<Dynamic> checkpoint_;
};

// The hook's factory for FluidSolver<3>: checks the geometry (triangles, thickness per node)
// and the case part, and builds the model at rest at time 0. The 3D lattice spacing is the
// case's virtual_spacing_ratio only where the case sets it (else 1, see ThinWall3DSettings).
std::unique_ptr<ImmersedSurfaceModel<3>> make_thin_wall_model_3d(const ImmersedSurfaceGeometry<3>& geometry,
                                                                 const FluidSettings<3>& fluid,
                                                                 const valvefsi::cases::FluidThinWalls& walls);

}  // namespace valvefsi::fluid::thin_wall
