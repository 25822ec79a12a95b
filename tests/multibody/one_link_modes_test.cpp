// The two-link model's one-link case, against a closed form: with joint A
// held (a hub far heavier than the arm) and link 2 all but weightless, link 1
// is a beam clamped at its hub carrying RB2 at its tip. Its assumed modes
// (phi2, phi3: a cubic in x, docs/two-link.md) give the two-term Ritz
// frequencies of that beam, the roots of det(K - w^2 M) = 0 with
//   K = EI/L^3 [[12, -6 L], [-6 L, 4 L^2]],
//   M = rho A L [[13/35, -11 L/210], [-11 L/210, L^2/105]] + diag(m_t, J_t),
// the textbook cubic beam element plus the tip body's mass and rotary
// inertia: without a tip body 3.533 sqrt(EI / (rho A L^4)) rad/s, within
// 0.5 % of the exact cantilever's 3.516.
#include <cmath>
#include <numbers>
#include <vector>

#include <catch2/catch.hpp>

#include "multibody/two_link_modes.h"
#include "tests/multibody/two_link_reference.h"

namespace impactlab {
namespace {

// The two-term Ritz frequencies (Hz) of a clamped beam with a tip body.
std::vector<double> ClampedBeamWithTipBody(const TwoLinkBeam& beam, const TwoLinkBody& tip) {
  const double l = beam.length_m, ei = beam.flexural_rigidity_n_m2;
  const double rho = beam.mass_per_length_kg_per_m;
  const double k11 = 12.0 * ei / (l * l * l), k12 = -6.0 * ei / (l * l), k22 = 4.0 * ei / l;
  const double m11 = rho * l * 13.0 / 35.0 + tip.mass_kg, m12 = -rho * l * l * 11.0 / 210.0,
               m22 = rho * l * l * l / 105.0 + tip.inertia_kg_m2;
  // det(K - lambda M) = a lambda^2 + b lambda + c.
  const double a = m11 * m22 - m12 * m12;
  const double b = -(k11 * m22 + k22 * m11 - 2.0 * k12 * m12);
  const double c = k11 * k22 - k12 * k12;
  const double root = std::sqrt(b * b - 4.0 * a * c);
  std::vector<double> hz;
  for (double lambda : {(-b - root) / (2.0 * a), (-b + root) / (2.0 * a)}) {
    hz.push_back(std::sqrt(lambda) / (2.0 * std::numbers::pi));
  }
  return hz;
}

TEST_CASE(
    "two-link: the one-link case rings at the clamped beam's Ritz frequencies with its tip "
    "body") {
  TwoLinkParameters p = testing::ConservativeParameters();
  p.hub1.inertia_kg_m2 = 1e5;  // joint A held: the arm's own inertia about it is ~0.3 kg m^2
  // Link 2 all but weightless: its masses 1e-5 of RB2's.
  p.beam2.mass_per_length_kg_per_m = 1e-5;
  p.hub3 = {0.0, 0.0};
  p.tool.body = {0.0, 0.0};
  p.drive_b.equivalent_inertia_kg_m2 = 1e-6;
  const TwoLinkModel model(p);
  TwoLinkVector q = TwoLinkVector::Zero();
  q(kLink1Angle) = q(kGearboxAAngle) = 0.9;
  const std::vector<VibrationMode> modes =
      LinearisedModes(model, q, TwoLinkVector::Zero(), DriveVoltages{}, false);
  const std::vector<double> ritz = ClampedBeamWithTipBody(p.beam1, p.body2);
  for (double expected_hz : ritz) {
    const VibrationMode* nearest = nullptr;
    for (const VibrationMode& m : modes) {
      if (!nearest ||
          std::abs(m.frequency_hz - expected_hz) < std::abs(nearest->frequency_hz - expected_hz)) {
        nearest = &m;
      }
    }
    REQUIRE(nearest);
    INFO("Ritz " << expected_hz << " Hz, linearised " << nearest->frequency_hz << " Hz");
    CHECK(nearest->frequency_hz == Approx(expected_hz).epsilon(1e-4));
    CHECK(nearest->damping_ratio == Approx(0.0).margin(1e-6));
  }
  // Without a tip body, the textbook 3.533 sqrt(EI / (rho A L^4)).
  const TwoLinkBody none{0.0, 0.0};
  const TwoLinkBeam& beam = p.beam1;
  CHECK(ClampedBeamWithTipBody(beam, none)[0] * 2.0 * std::numbers::pi ==
        Approx(3.533 * std::sqrt(beam.flexural_rigidity_n_m2 /
                                 (beam.mass_per_length_kg_per_m * std::pow(beam.length_m, 4))))
            .epsilon(1e-3));
}

}  // namespace
}  // namespace impactlab
