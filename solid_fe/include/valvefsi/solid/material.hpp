#pragma once
// The leaflet materials as one closed set: element loops are written once as templates and
// dispatched per material with std::visit outside the loop, so the inner loop has no virtual call.
#include <string>
#include <variant>

#include "valvefsi/solid/mhgo.hpp"
#include "valvefsi/solid/neo_hookean.hpp"
#include "valvefsi/solid/ogden.hpp"
#include "valvefsi/solid/saint_venant_kirchhoff.hpp"

namespace valvefsi::solid {

using Material = std::variant<Ogden, Mhgo, NeoHookean, SaintVenantKirchhoff>;

inline PlaneStressResponse plane_stress(const Material& m, const Eigen::Matrix2d& C,
                                        bool with_tangent = true) {
  return std::visit([&](const auto& law) { return law.plane_stress(C, with_tangent); }, m);
}

inline double initial_membrane_modulus(const Material& m) {
  return std::visit([](const auto& law) { return law.initial_membrane_modulus(); }, m);
}

inline std::string material_name(const Material& m) {
  struct Namer {
    std::string operator()(const Ogden&) const { return "ogden"; }
    std::string operator()(const Mhgo&) const { return "mhgo"; }
    std::string operator()(const NeoHookean&) const { return "neo_hookean"; }
    std::string operator()(const SaintVenantKirchhoff&) const { return "saint_venant_kirchhoff"; }
  };
  return std::visit(Namer{}, m);
}

}  // namespace valvefsi::solid
