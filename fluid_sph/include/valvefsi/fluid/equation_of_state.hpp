#pragma once
// Linear Mie-Grueneisen equation of state, the reference's eq. 5 with s = 0 and Gamma0 = 0:
//   p = rho0 c0^2 eta,  eta = 1 - rho0 / rho.
// Densities travel as the excess rho - rho0 so that single precision keeps the pressure
// accurate even when rho0 c0^2 is 10^10 Pa (blood at c0 = 145 m/s).
namespace valvefsi::fluid {

struct LinearMieGruneisen {
  double rest_density;
  double sound_speed;

  double bulk_modulus() const { return rest_density * sound_speed * sound_speed; }
  // p(rho) with rho = rest_density + density_excess.
  double pressure(double density_excess) const {
    return bulk_modulus() * density_excess / (rest_density + density_excess);
  }
  // Inverse: the density excess at which the pressure is p.
  double density_excess(double p) const {
    const double k = bulk_modulus();
    return rest_density * p / (k - p);
  }
};

}  // namespace valvefsi::fluid
