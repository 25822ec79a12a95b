// The impact law at one frictional contact (multibody/contact_impulse.h),
// against closed forms and the laws of physics, over random contacts.
#include "multibody/contact_impulse.h"

#include <cmath>
#include <random>

#include <Eigen/LU>
#include <catch2/catch.hpp>

namespace impactlab {
namespace {

// A random contact: a positive definite Delassus matrix (the tangential row
// strongly coupled to the normal one in a fair share of them), an approach.
struct RandomContact {
  Eigen::Matrix2d delassus;
  Eigen::Vector2d before;
};

RandomContact Draw(std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Matrix2d a;
  a << unit(rng), unit(rng), unit(rng), unit(rng);
  RandomContact c;
  c.delassus = a * a.transpose() + 0.02 * Eigen::Matrix2d::Identity();
  c.before = Eigen::Vector2d(-0.05 - std::abs(unit(rng)), 0.6 * unit(rng));
  return c;
}

// The kinetic energy at the contact: 1/2 u^T W^-1 u is what a stick-plastic
// impact removes, the most any impact at this contact can.
double MostLoss(const RandomContact& c) {
  return 0.5 * c.before.dot(c.delassus.lu().solve(c.before));
}

ContactImpulseLaw Law(double mu, RestitutionLaw restitution, double e) {
  ContactImpulseLaw law;
  law.friction_coefficient = mu;
  law.restitution = restitution;
  law.restitution_coefficient = e;
  return law;
}

}  // namespace

TEST_CASE("contact impulse: friction never does positive work, over 3000 random impacts") {
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int stopped = 0, reversed = 0, stuck = 0;
  for (int i = 0; i < 3000; ++i) {
    const RandomContact c = Draw(rng);
    const auto restitution = static_cast<RestitutionLaw>(i % 3);
    const ContactImpulseLaw law = Law(uniform(rng), restitution, i % 2 ? uniform(rng) : 0.0);
    ContactImpulse out;
    try {
      out = ResolveContactImpulse(c.delassus, c.before, law);
    } catch (const std::domain_error&) {
      continue;  // a jam: checked below
    }
    const double scale = MostLoss(c);
    INFO("impact " << i << ", mu " << law.friction_coefficient << ", e "
                   << law.restitution_coefficient);
    CHECK(out.friction_work_j <= 1e-14 * scale);
    CHECK(out.impulse(0) > 0.0);
    CHECK(std::abs(out.impulse(1)) <= law.friction_coefficient * out.impulse(0) * (1 + 1e-12));
    // The works add up to the kinetic energy's change, 1/2 (u- + u+) . P.
    const double change = 0.5 * (c.before + out.velocity_after).dot(out.impulse);
    CHECK(out.normal_work_j + out.friction_work_j == Approx(change).margin(1e-12 * scale));
    CHECK(out.velocity_after(0) >= -1e-12 * std::abs(c.before(0)));
    stopped += out.slip_stopped;
    reversed += out.slip_reversed;
    stuck += out.sticks;
  }
  WARN("slip stopped in " << stopped << ", reversed in " << reversed << ", stuck at the end in "
                          << stuck << " of 3000");
  CHECK(reversed > 100);
  CHECK(stuck > 100);
}

TEST_CASE("contact impulse: the energetic coefficient bounds the energy lost") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const RandomContact c = Draw(rng);
    const double e = uniform(rng);
    ContactImpulse out;
    try {
      out = ResolveContactImpulse(c.delassus, c.before,
                                  Law(uniform(rng), RestitutionLaw::kEnergetic, e));
    } catch (const std::domain_error&) {
      continue;
    }
    const double lost = -(out.normal_work_j + out.friction_work_j), most = MostLoss(c);
    CHECK(lost >= -1e-14 * most);
    CHECK(lost <= most * (1 + 1e-12));
  }
  // Frictionless: the loss is (1 - e^2) u_n^2 / (2 W_nn), and the three laws agree.
  const RandomContact c = Draw(rng);
  const double e = 0.6, u = c.before(0), w = c.delassus(0, 0);
  for (RestitutionLaw restitution :
       {RestitutionLaw::kEnergetic, RestitutionLaw::kNewton, RestitutionLaw::kPoisson}) {
    const ContactImpulse out =
        ResolveContactImpulse(c.delassus, c.before, Law(0.0, restitution, e));
    CHECK(out.impulse(0) == Approx(-(1 + e) * u / w).epsilon(1e-13));
    CHECK(out.impulse(1) == 0.0);
    CHECK(out.velocity_after(0) == Approx(-e * u).epsilon(1e-12));
    CHECK(-(out.normal_work_j + out.friction_work_j) ==
          Approx((1 - e * e) * u * u / (2 * w)).epsilon(1e-12));
  }
}

TEST_CASE("contact impulse: Newton's and Poisson's coefficients end the impulse as they say") {
  std::mt19937 rng(11);
  for (int i = 0; i < 200; ++i) {
    const RandomContact c = Draw(rng);
    try {
      const ContactImpulse newton =
          ResolveContactImpulse(c.delassus, c.before, Law(0.3, RestitutionLaw::kNewton, 0.5));
      CHECK(newton.velocity_after(0) == Approx(-0.5 * c.before(0)).epsilon(1e-10));
      const ContactImpulse poisson =
          ResolveContactImpulse(c.delassus, c.before, Law(0.3, RestitutionLaw::kPoisson, 0.5));
      CHECK(poisson.impulse(0) == Approx(1.5 * poisson.compression_impulse_n_s).epsilon(1e-12));
    } catch (const std::domain_error&) {
    }
  }
}

TEST_CASE("contact impulse: the paper's law is recovered where the slip keeps its direction") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int kept = 0, stuck = 0, differ = 0;
  for (int i = 0; i < 2000; ++i) {
    const RandomContact c = Draw(rng);
    const double mu = uniform(rng);
    ContactImpulse incremental;
    try {
      incremental =
          ResolveContactImpulse(c.delassus, c.before, Law(mu, RestitutionLaw::kEnergetic, 0));
    } catch (const std::domain_error&) {
      continue;
    }
    ContactImpulseLaw paper_law = Law(mu, RestitutionLaw::kEnergetic, 0);
    paper_law.friction = ImpactFriction::kPaper;
    const ContactImpulse paper = ResolveContactImpulse(c.delassus, c.before, paper_law);
    const double tolerance = 1e-12 * incremental.impulse.norm();
    if (!incremental.slip_stopped) {
      ++kept;
      CHECK((incremental.impulse - paper.impulse).norm() <= tolerance);
    } else if (incremental.sticks) {
      // Stopped and stuck: both velocities end at 0, the paper's sticking impulse.
      ++stuck;
      CHECK((incremental.impulse - paper.impulse).norm() <= tolerance);
    } else {
      ++differ;  // reversed: the paper's friction works against the motion no longer
      CHECK(paper.friction_work_j > incremental.friction_work_j);
    }
  }
  WARN("slip kept its direction in " << kept << ", stopped and stuck in " << stuck
                                     << ", reversed in " << differ);
  CHECK(kept > 500);
  CHECK(stuck > 100);
  CHECK(differ > 50);
}

TEST_CASE("contact impulse: a contact the impulse cannot stop is refused as a jam") {
  // Strong coupling, large mu: the normal velocity falls as P grows.
  Eigen::Matrix2d w;
  w << 1.0, 0.9, 0.9, 1.0;
  ContactImpulseLaw law = Law(2.0, RestitutionLaw::kEnergetic, 0.0);
  CHECK_THROWS_WITH(ResolveContactImpulse(w, Eigen::Vector2d(-1.0, 1.0), law),
                    Catch::Contains("jams"));
  // Not approaching: no impulse.
  const ContactImpulse none = ResolveContactImpulse(w, Eigen::Vector2d(0.1, 1.0), law);
  CHECK(none.impulse.norm() == 0.0);
}

}  // namespace impactlab
