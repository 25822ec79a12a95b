// Sessions of typed-in maxima and contact times drawn from any contact law:
// the truth for the contact-law fits' tests and their coverage benchmark
// (bench/contact_law_coverage.cpp). Each run is released from its X0, the
// rebound history follows the law impact by impact (model/rebound_history.h),
// and Gaussian reading errors of the stated sigmas are added.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "model/contact.h"
#include "model/pendulum.h"

namespace impactlab {

struct LawSessionOptions {
  std::vector<double> initial_displacements{0.115, 0.234, 0.323, 0.405, 0.478, 0.598};
  int maxima = 5;                    // rebounds 0 .. maxima-1 in session numbering
  int first_rebound = 1;             // rebound counted from the first impact that is called 0
  int contact_impact = 2;            // the impact whose contact time each run measures (from 1)
  double xmax_sigma = 5e-4;          // length units
  double contact_time_sigma = 2e-6;  // s; 0 = no contact times
  // The reading errors drawn are this times the stated sigmas: > 1 draws a
  // session whose sigmas understate its scatter (the Birge scaling's test).
  double error_scale = 1.0;
  std::uint64_t seed = 1;
};

struct LawSessionRun {
  double initial_displacement = 0.0;
  std::vector<double> xmax, xmax_sigma;  // session numbering, with reading errors
  std::vector<double> true_xmax;
  double contact_time = 0.0, contact_time_sigma = 0.0;  // with its error (sigma 0: none)
  double true_contact_time = 0.0;
  int contact_rebound = 0;  // session rebound before the measured impact (-1: the release)
};

// Throws what SimulateRebounds throws (a swing past the horizontal) or
// NoSeparationError from the law.
std::vector<LawSessionRun> DrawLawSession(const Pendulum& pendulum, const ContactLaw& law,
                                          const LawSessionOptions& options);

// The drawn runs as a manifest's [[run]] tables (typed-in maxima and contact
// times with their uncertainties), for a test or bench to append to its own
// manifest text.
std::string LawSessionRunsToml(const std::vector<LawSessionRun>& runs);

}  // namespace impactlab
