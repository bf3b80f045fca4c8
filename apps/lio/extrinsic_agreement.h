// Whether the extrinsic a run uses agrees with the one its data carry (issue 40). A config
// `extrinsic:` overrides a bag's /tf_static, a preset or a dataset's own value; one written for
// another sensor gave 0.5 m of error with every scan `ok` and exit 0, announced by an INFO line
// only. The run now says so loudly (log, summary line, evaluation.txt `extrinsic_disagreement`)
// when the two differ by more than 1° or 1 cm, naming both values.
#pragma once

#include <string>

#include "ctlio/manifolds/se3.h"

namespace ctlio::lioapp {

struct ExtrinsicTolerance {
  double max_rotation_deg = 1.0;
  double max_translation_m = 0.01;
};

// "T_imu_lidar: translation [x y z] m, rotation a deg about [u v w]" of `T`.
std::string DescribeExtrinsic(const SE3& T);

// Empty when `used` and `data` agree within `tolerance`; otherwise
// "<used_name> vs <data_name>: 12.3 deg, 4.5 cm (<used_name>: …; <data_name>: …)".
std::string ExtrinsicDisagreement(const SE3& used, const std::string& used_name, const SE3& data,
                                  const std::string& data_name,
                                  const ExtrinsicTolerance& tolerance = {});

}  // namespace ctlio::lioapp
