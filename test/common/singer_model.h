// The Singer motion model of SPEC §4 (Singer-LIO on Newer College): Qc = [5000 ×3, 500 ×3],
// α = [0 ×3, 100 ×3] — the model the factor tests and benchmarks evaluate the GP factors with.
#pragma once

#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::testing {

// `singer` false: the same Qc with α = 0 (white noise on jerk).
inline gp::SingerModel<6> NewerCollegeSingerModel(bool singer = true) {
  Vec6 qc, alpha;
  qc << 5000, 5000, 5000, 500, 500, 500;
  alpha << 0, 0, 0, 100, 100, 100;
  if (!singer) alpha.setZero();
  return gp::SingerModel<6>(qc, alpha);
}

}  // namespace ctlio::testing
