// The manipulator's first-order state y = (q, q'), as the ODE integrator
// (model/ode_integrator.h) carries it.
#pragma once

#include <array>

#include "multibody/two_link_model.h"

namespace impactlab {

using TwoLinkState = std::array<double, 2 * kTwoLinkCoordinates>;

inline TwoLinkState JoinState(const TwoLinkVector& q, const TwoLinkVector& v) {
  TwoLinkState y;
  for (int i = 0; i < kTwoLinkCoordinates; ++i) {
    y[i] = q(i);
    y[i + kTwoLinkCoordinates] = v(i);
  }
  return y;
}

inline void SplitState(const TwoLinkState& y, TwoLinkVector* q, TwoLinkVector* v) {
  for (int i = 0; i < kTwoLinkCoordinates; ++i) {
    (*q)(i) = y[i];
    (*v)(i) = y[i + kTwoLinkCoordinates];
  }
}

}  // namespace impactlab
