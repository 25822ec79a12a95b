// An impact at one frictional contact point, resolved at the contact
// (docs/two-link.md, "The impact law"): given the Delassus matrix
// W = G M^-1 G^T of the contact's normal and tangential rows G and the contact
// velocity u- = G q'- before the impact (u_n < 0: approaching), the impulse
// P = (P_n, P_t) and the velocity u+ = u- + W P after it.
//
// The incremental law (Darboux-Keller, as in Stronge's "Impact Mechanics",
// ch. 5) follows the impulse as it grows, with the normal impulse p as the
// clock: du/dp = W (1, dP_t/dp). While the tip slips with sign s, Coulomb's
// law holds at every instant, dP_t/dp = -mu s; the slip may stop during the
// impulse, and then it sticks (dP_t/dp = -W_tn / W_tt, inside the cone when
// |W_tn| <= mu W_tt) or it resumes in the one direction the dynamics allow,
// sign(W_tn). Friction therefore never does positive work.
//
// Restitution ends the impulse, after compression (u_n reaching 0 at p_c):
//   kNewton     u_n+ = -e u_n-                 (kinematic)
//   kPoisson    P_n = (1 + e) p_c              (kinetic)
//   kEnergetic  the normal force's work during restitution is e^2 times its
//               work during compression        (Stronge's energetic e*)
// With e = 0 the three are the same plastic impact, the paper's. Only the
// energetic law bounds the energy lost for every friction and geometry.
//
// The paper's law (kPaper) is kept for comparison: stick when the impulse
// that stops both velocities lies in the friction cone, else slide with
// P_t = -mu sign(slip before) P_n throughout. It agrees with the incremental
// law where the slip keeps its direction, and does positive friction work
// where the slip would stop or reverse during the impulse.
#pragma once

#include <Eigen/Core>

namespace impactlab {

enum class ImpactFriction { kIncremental, kPaper };
enum class RestitutionLaw { kNewton, kPoisson, kEnergetic };

struct ContactImpulseLaw {
  double friction_coefficient = 0.0;  // mu
  ImpactFriction friction = ImpactFriction::kIncremental;
  RestitutionLaw restitution = RestitutionLaw::kEnergetic;
  double restitution_coefficient = 0.0;  // e, in [0, 1]; 0: plastic
};

struct ContactImpulse {
  Eigen::Vector2d impulse = Eigen::Vector2d::Zero();         // (P_n, P_t), N s
  Eigen::Vector2d velocity_after = Eigen::Vector2d::Zero();  // u+ = u- + W P, m/s
  double compression_impulse_n_s = 0.0;                      // p_c
  // The work of each impulse over the impact (their sum is the kinetic
  // energy's change): the normal one's, and friction's (<= 0 for the
  // incremental law).
  double normal_work_j = 0.0;
  double friction_work_j = 0.0;
  bool sticks = false;         // the slip is 0 at the end
  bool slip_stopped = false;   // the slip came to rest during the impulse
  bool slip_reversed = false;  // ... and resumed the other way
};

// Throws std::domain_error when the impulse cannot stop the approach (the
// normal velocity falls as the impulse grows: a frictional jam, Painlevé's
// paradox at impact) and std::invalid_argument for a bad law.
ContactImpulse ResolveContactImpulse(const Eigen::Matrix2d& delassus,
                                     const Eigen::Vector2d& velocity_before,
                                     const ContactImpulseLaw& law);

}  // namespace impactlab
