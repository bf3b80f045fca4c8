// Drains a dataset source the way the odometry does: every scan, then the ground truth.
#pragma once

#include "ctlio/io/dataset.h"

namespace ctlio::fuzz {

inline void Drain(io::DataSource& source) {
  io::ScanFrame frame;
  while (source.Next(&frame)) {
  }
  source.GroundTruth();
}

}  // namespace ctlio::fuzz
