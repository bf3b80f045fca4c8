// The map's error as the map is built (window.pose_covariance_map_growth g): the covariance a
// scan's registration inherits from the points earlier scans inserted. Every scan measures its
// pose relative to the map, so its error in the map frame is e_w(k) = e_rel(k) + m(k−1), with
// e_rel ~ N(0, Σ_rel(k)) the error the window describes (conditioned on an exact map) and m the
// map's own error. The first scan's map is exact (it fixes the gauge). Scan k then inserts a
// fraction β_k = n_k / N_k of the map's points (n_k inserted, N_k in the map after), each carrying
// its error e_w(k); a map registered as a whole moves by the mean of its points' errors:
//   m(k) = (1 − β_k)·m(k−1) + β_k·e_w(k) = m(k−1) + β_k·e_rel(k)
//   Σ_map(k) = Σ_map(k−1) + g·β_k²·Σ_rel(k)                                          (1)
// with g = 1 the model as derived (e_rel(k) independent of m(k−1)). A map that keeps growing
// into new places keeps β large; one whose voxels are full (a room seen from the start) freezes:
// the start-up error of a sparse sensor stays in the map while the window's covariance, which
// treats the map as exact, shrinks (docs/experiments/covariance.md, "16 beams"). Covariance
// only: the estimate is unchanged.
#pragma once

#include <cstddef>

#include "ctlio/manifolds/types.h"

namespace ctlio::lio {

class MapGrowthCovariance {
 public:
  // Σ_map of the map the newest scan was registered against (before its own insertion is
  // accounted): the covariance to add to that scan's Σ_rel.
  const Mat6& map() const { return map_; }

  // Scan k's relative covariance Σ_rel(k) (the window's, in ε), whose insertion is accounted by
  // the next Inserted call.
  void Registered(const Mat6& relative);

  // Scan k inserted `inserted` points into a map of `map_points` points after the insertion:
  // (1) with the Σ_rel of the last Registered (none since the previous Inserted: nothing, e.g.
  // the first scan or a scan without a covariance). gain g ≥ 0.
  void Inserted(size_t inserted, size_t map_points, double gain);

 private:
  Mat6 map_ = Mat6::Zero();
  Mat6 pending_ = Mat6::Zero();
  bool has_pending_ = false;
};

}  // namespace ctlio::lio
