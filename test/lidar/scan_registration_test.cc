// ScanRegistration keeps each keypoint's residual block across its association rounds (the new
// plane written into the block's cost function) instead of removing every block and adding it
// again, and may keep a keypoint's plane while the keypoint moves less than
// reassociation_distance. Checked here: which blocks are added, updated and removed, and that
// the solution equals the one of fresh blocks every round (a reference loop written out below,
// the registration before persistent blocks) to round-off, for the rigid, the continuous and the
// continuous-with-extrinsic terms, with and without plane reuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "sweep_registration.h"

namespace ctlio::lio {
namespace {

// A 20 × 16 × 6 m room with a ramp, sampled every 0.15 m, with 1 cm noise so that the kNN plane
// of a point depends on where it is (a new association is a different residual).
std::vector<Vec3> RoomPoints(std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Vec3> points;
  auto add = [&](const Vec3& p) { points.push_back(p + Vec3(noise(rng), noise(rng), noise(rng))); };
  const double h = 0.15;
  for (double a = -10.0; a <= 10.0; a += h) {
    for (double b = -8.0; b <= 8.0; b += h) {
      add(Vec3(a, b, 0.0));  // floor
      add(Vec3(a, b, 6.0));  // ceiling
    }
    for (double z = 0.0; z <= 6.0; z += h) {
      add(Vec3(a, -8.0, z));
      add(Vec3(a, 8.0, z));
    }
  }
  for (double b = -8.0; b <= 8.0; b += h) {
    for (double z = 0.0; z <= 6.0; z += h) {
      add(Vec3(-10.0, b, z));
      add(Vec3(10.0, b, z));
    }
  }
  for (double a = 2.0; a <= 6.0; a += h) {  // a ramp: a plane of every orientation is seen
    for (double b = -3.0; b <= 3.0; b += h) add(Vec3(a, b, 0.5 * (a - 2.0) + 0.2 * b + 1.0));
  }
  return points;
}

struct Scene {
  VoxelMap map{LidarFrontend::MapOptions(LidarFrontendOptions())};
  std::vector<TimedPoint> keypoints;  // robot frame, times in [0, 0.1]
  SE3 T_rm_true;
  SE3 T_rm_initial;
};

Scene MakeScene(uint32_t seed, int num_keypoints) {
  std::mt19937 rng(seed);
  Scene s;
  const std::vector<Vec3> room = RoomPoints(rng);
  s.map.Insert(room);
  s.T_rm_true = SE3::Exp((Vec6() << 0.3, -0.2, -2.5, 0.02, -0.01, 0.3).finished());
  // Keypoints: map points away from the edges, in the robot frame.
  std::uniform_int_distribution<size_t> pick(0, room.size() - 1);
  std::uniform_real_distribution<double> time(0.0, 0.1);
  while (static_cast<int>(s.keypoints.size()) < num_keypoints) {
    const Vec3& p = room[pick(rng)];
    if (std::abs(p.x()) > 9.0 || std::abs(p.y()) > 7.0) continue;
    s.keypoints.push_back({s.T_rm_true * p, time(rng)});
  }
  std::sort(s.keypoints.begin(), s.keypoints.end(),
            [](const TimedPoint& a, const TimedPoint& b) { return a.time < b.time; });
  // An initial error of ~25 cm and ~2°: the associations change between the rounds.
  s.T_rm_initial =
      SE3::Exp((Vec6() << 0.15, -0.1, 0.15, 0.02, -0.015, 0.025).finished()) * s.T_rm_true;
  return s;
}

LidarFrontendOptions Options(double reassociation_distance) {
  LidarFrontendOptions o;
  o.max_iterations = 4;
  o.solver_iterations = 3;
  // Every round runs: both loops do the same number of solves.
  o.convergence_translation = 0.0;
  o.convergence_rotation = 0.0;
  o.reassociation_distance = reassociation_distance;
  return o;
}

// The registration loop with fresh residual blocks in every round (before persistent blocks),
// the same association and the same plane reuse rule. Returns the last round's association count.
int ReferenceRegister(const VoxelMap& map, const LidarFrontendOptions& options, LidarTerm* term,
                      SlidingWindow* window) {
  PlaneAssociator associator(map, options);
  const size_t n = term->num_keypoints();
  std::vector<ceres::ResidualBlockId> blocks;
  std::vector<PlaneAssociation> planes(n);
  std::vector<bool> associated(n, false);
  std::vector<Vec3> searched_at(n);
  const double d = options.reassociation_distance;
  for (int round = 0; round < options.max_iterations; ++round) {
    for (ceres::ResidualBlockId id : blocks) window->RemoveResidualBlock(id);
    blocks.clear();
    term->BeginRound();
    std::unique_ptr<ceres::LossFunction> loss = MakeLidarLoss(options);
    for (size_t i = 0; i < n; ++i) {
      Vec3 q, p_map;
      term->Locate(i, &q, &p_map);
      if (associated[i] && (p_map - searched_at[i]).norm() < d) {
        planes[i].point_robot = q;
      } else {
        searched_at[i] = p_map;
        associated[i] = associator.Associate(q, p_map, &planes[i]);
      }
      if (!associated[i]) continue;
      PlaneAssociation a = planes[i];
      a.weight /= options.point_noise_sigma;
      blocks.push_back(term->AddResidual(i, a, loss.get(), window));
    }
    if (!blocks.empty()) loss.release();
    window->Solve();
  }
  return static_cast<int>(blocks.size());
}

// Rigid (one pose) registration of the scene by Register or by the reference loop.
SE3 RegisterRigid(const Scene& s, const LidarFrontendOptions& options, bool reference,
                  int* associations) {
  SlidingWindow window(sweep::SweepWindowOptions(options));
  window.AddPoseState(0, s.T_rm_initial);
  sweep::RigidLidarTerm term(0, s.keypoints, window);
  if (reference) {
    *associations = ReferenceRegister(s.map, options, &term, &window);
  } else {
    const RegistrationSummary summary = ScanRegistration(options, OdometryConfig().min_associations)
                                            .Register(s.map, &term, &window);
    *associations = summary.associations;
    EXPECT_EQ(static_cast<int>(summary.lidar_blocks.size()), summary.associations);
    EXPECT_EQ(window.num_residual_blocks(), summary.associations);
  }
  return window.Pose(0);
}

// Continuous registration (two GP knots, Singer prior), optionally through the extrinsic
// variant of the factor (extrinsic held constant: it is the factor path that is checked).
std::vector<double> RegisterContinuous(const Scene& s, const LidarFrontendOptions& options,
                                       bool with_extrinsic, bool reference, int* associations) {
  const gp::SingerModel<6> model(Vec6::Constant(100.0), Vec6::Constant(1.0));
  SlidingWindow window(sweep::SweepWindowOptions(options));
  const KnotKeys a = KnotKeys::ForKnot(0), b = KnotKeys::ForKnot(1);
  for (const KnotKeys& keys : {a, b}) {
    window.AddPoseState(keys.pose, s.T_rm_initial);
    window.AddVectorState(keys.velocity, Vec6::Zero());
    window.AddVectorState(keys.acceleration, Vec6::Zero());
  }
  window.AddResidualBlock(new gp::SingerPrior(model, 0.1), nullptr, KnotPair(a, b));
  std::unique_ptr<ContinuousLidarTerm> term;
  if (with_extrinsic) {
    window.AddPoseState(kExtrinsicKey, SE3());
    window.SetStateConstant(kExtrinsicKey, true);
    term =
        std::make_unique<ContinuousLidarTerm>(model, 0.0, 0.1, a, b, s.keypoints, SE3(), &window);
  } else {
    term = std::make_unique<ContinuousLidarTerm>(model, 0.0, 0.1, a, b, s.keypoints, &window);
  }
  if (reference) {
    *associations = ReferenceRegister(s.map, options, term.get(), &window);
  } else {
    const RegistrationSummary summary = ScanRegistration(options, OdometryConfig().min_associations)
                                            .Register(s.map, term.get(), &window);
    *associations = summary.associations;
    EXPECT_EQ(window.num_residual_blocks(), summary.associations + 1);  // + the prior
  }
  std::vector<double> x;
  for (const KnotKeys& keys : {a, b}) {
    for (StateId id : {keys.pose, keys.velocity, keys.acceleration}) {
      const Eigen::VectorXd v = window.Vector(id);
      x.insert(x.end(), v.data(), v.data() + v.size());
    }
  }
  return x;
}

double PoseDistance(const SE3& a, const SE3& b) { return (a * b.Inverse()).Log().norm(); }

TEST(ScanRegistration, PersistentBlocksSolveAsFreshBlocks) {
  const Scene s = MakeScene(41, 300);
  // 0: search every round; 0.02 m: planes kept for the small late steps only; 1 m: never searched
  // again once found.
  for (const double d : {0.0, 0.02, 1.0}) {
    const LidarFrontendOptions o = Options(d);
    int kept_count = 0, fresh_count = 0;
    const SE3 kept = RegisterRigid(s, o, false, &kept_count);
    const SE3 fresh = RegisterRigid(s, o, true, &fresh_count);
    EXPECT_EQ(kept_count, fresh_count) << d;
    EXPECT_GT(kept_count, 250) << d;
    EXPECT_LT(PoseDistance(kept, fresh), 1e-9) << d;
    // And it registered (from 0.24): to ~2 cm searching every round (0.019 with GCC, 0.024 with
    // clang: the noisy room's associations differ in the last bits), while the round-0 planes of
    // d = 1 m (found 25 cm off) leave it far from the truth.
    if (d < 0.1) {
      EXPECT_LT(PoseDistance(kept, s.T_rm_true), 0.15 * PoseDistance(s.T_rm_initial, s.T_rm_true))
          << d;
    }
    for (const bool extrinsic : {false, true}) {
      const std::vector<double> x = RegisterContinuous(s, o, extrinsic, false, &kept_count);
      const std::vector<double> y = RegisterContinuous(s, o, extrinsic, true, &fresh_count);
      EXPECT_EQ(kept_count, fresh_count) << d << " " << extrinsic;
      ASSERT_EQ(x.size(), y.size());
      for (size_t j = 0; j < x.size(); ++j) {
        EXPECT_NEAR(x[j], y[j], 1e-9) << "parameter " << j << ", d " << d << " " << extrinsic;
      }
    }
  }
  // The reuse is not a no-op: keeping the round-0 planes ends elsewhere than searching again.
  int count = 0;
  EXPECT_GT(PoseDistance(RegisterRigid(s, Options(0.0), false, &count),
                         RegisterRigid(s, Options(1.0), false, &count)),
            1e-7);
}

// A term that hides chosen keypoints (placed far outside the map: no plane) in chosen rounds and
// records what the registration does with each keypoint's residual.
class HidingTerm final : public LidarTerm {
 public:
  HidingTerm(LidarTerm* inner, std::map<size_t, std::set<int>> hidden)
      : inner_(inner), hidden_(std::move(hidden)) {}
  size_t num_keypoints() const override { return inner_->num_keypoints(); }
  void BeginRound() override {
    ++round_;
    inner_->BeginRound();
  }
  void Locate(size_t i, Vec3* q, Vec3* p_map) override {
    inner_->Locate(i, q, p_map);
    const auto it = hidden_.find(i);
    if (it != hidden_.end() && it->second.count(round_) != 0) *p_map += Vec3(1000.0, 0.0, 0.0);
  }
  ceres::ResidualBlockId AddResidual(size_t i, const PlaneAssociation& a, ceres::LossFunction* loss,
                                     SlidingWindow* window) override {
    const ceres::ResidualBlockId id = inner_->AddResidual(i, a, loss, window);
    added[i].push_back({round_, id});
    return id;
  }
  void UpdateResidual(size_t i, const PlaneAssociation& a) override {
    inner_->UpdateResidual(i, a);
    updated[i].push_back(round_);
  }
  SE3 NewestPose() const override { return inner_->NewestPose(); }

  std::map<size_t, std::vector<std::pair<int, ceres::ResidualBlockId>>> added;
  std::map<size_t, std::vector<int>> updated;

 private:
  LidarTerm* inner_;
  std::map<size_t, std::set<int>> hidden_;
  int round_ = -1;
};

TEST(ScanRegistration, KeptUpdatedRemovedAndAddedBlocks) {
  const Scene s = MakeScene(42, 200);
  for (const double d : {0.0, 1.0}) {
    const LidarFrontendOptions o = Options(d);
    SlidingWindow window(sweep::SweepWindowOptions(o));
    window.AddPoseState(0, s.T_rm_initial);
    sweep::RigidLidarTerm rigid(0, s.keypoints, window);
    // Keypoint 0 loses its plane in round 1, keypoint 1 has none in round 0, keypoint 2 none
    // from round 2 on.
    HidingTerm term(&rigid, {{0, {1}}, {1, {0}}, {2, {2, 3}}});
    const RegistrationSummary summary =
        ScanRegistration(o, OdometryConfig().min_associations).Register(s.map, &term, &window);
    ASSERT_EQ(summary.rounds, 4);
    ASSERT_FALSE(summary.degenerate);
    const size_t n = s.keypoints.size();
    // Every keypoint that had a plane in all rounds got one block in round 0, updated in rounds
    // 1–3 (also with plane reuse: the reused plane is written as well).
    std::set<ceres::ResidualBlockId> expected;
    for (size_t i = 3; i < n; ++i) {
      if (term.added.count(i) == 0) continue;  // no plane anywhere (an edge of the room)
      ASSERT_EQ(term.added[i].size(), 1u) << i;
      EXPECT_EQ(term.added[i][0].first, 0) << i;
      EXPECT_EQ(term.updated[i], (std::vector<int>{1, 2, 3})) << i;
      expected.insert(term.added[i][0].second);
    }
    // Keypoint 0: added in round 0, removed in round 1, a new block in round 2, updated in 3.
    ASSERT_EQ(term.added[0].size(), 2u);
    EXPECT_EQ(term.added[0][0].first, 0);
    EXPECT_EQ(term.added[0][1].first, 2);
    EXPECT_EQ(term.updated[0], std::vector<int>{3});
    expected.insert(term.added[0][1].second);
    // Keypoint 1: added in round 1 (its plane searched then), updated in 2 and 3.
    ASSERT_EQ(term.added[1].size(), 1u);
    EXPECT_EQ(term.added[1][0].first, 1);
    EXPECT_EQ(term.updated[1], (std::vector<int>{2, 3}));
    expected.insert(term.added[1][0].second);
    // Keypoint 2: added in round 0, updated in round 1, removed in round 2 (with reuse too: it
    // moved 1000 m).
    ASSERT_EQ(term.added[2].size(), 1u);
    EXPECT_EQ(term.updated[2], std::vector<int>{1});
    // The summary's blocks are this round's, in keypoint order, and the window holds exactly
    // them.
    EXPECT_GT(summary.associations, 150);
    EXPECT_EQ(summary.associations, static_cast<int>(expected.size()));
    ASSERT_EQ(summary.lidar_blocks.size(), expected.size());
    EXPECT_EQ(
        std::set<ceres::ResidualBlockId>(summary.lidar_blocks.begin(), summary.lidar_blocks.end()),
        expected);
    EXPECT_EQ(summary.lidar_blocks.front(), term.added[0][1].second);
    EXPECT_EQ(summary.lidar_blocks[1], term.added[1][0].second);
    EXPECT_EQ(window.num_residual_blocks(), summary.associations);
    // It registered: searching every round well; keeping the round-0 planes (d = 1 m, found
    // ~25 cm off) only partly (0.19 of 0.24 with clang).
    EXPECT_LT(PoseDistance(window.Pose(0), s.T_rm_true),
              (d < 0.1 ? 0.6 : 0.9) * PoseDistance(s.T_rm_initial, s.T_rm_true))
        << d;
  }
}

// point_noise_angle: σ_i = √(σ² + (θ·|q_i|)²), the configured σ without it.
TEST(ScanRegistration, PointNoiseSigmaGrowsWithRange) {
  LidarFrontendOptions o;
  o.point_noise_sigma = 0.05;
  EXPECT_EQ(PointNoiseSigma(o, Vec3(30.0, 0.0, 0.0)), 0.05);
  o.point_noise_angle = 0.004;
  EXPECT_NEAR(PointNoiseSigma(o, Vec3(0.0, 6.0, 8.0)), std::sqrt(0.05 * 0.05 + 0.04 * 0.04), 1e-15);
  EXPECT_NEAR(PointNoiseSigma(o, Vec3(0.0, 0.0, 0.0)), 0.05, 1e-15);
  EXPECT_NEAR(PointNoiseSigma(o, Vec3(-30.0, 0.0, 0.0)), std::sqrt(0.05 * 0.05 + 0.12 * 0.12),
              1e-15);
}

// plane_thickness_noise: the plane's own scatter σ3 (times the factor) adds to σ_i in quadrature;
// without the factor the thickness is not used.
TEST(ScanRegistration, PointNoiseSigmaGrowsWithThePlanesThickness) {
  LidarFrontendOptions o;
  o.point_noise_sigma = 0.05;
  EXPECT_EQ(PointNoiseSigma(o, Vec3(30.0, 0.0, 0.0), 0.08), 0.05);
  o.plane_thickness_noise = 2.0;
  EXPECT_NEAR(PointNoiseSigma(o, Vec3(30.0, 0.0, 0.0), 0.03), std::sqrt(0.05 * 0.05 + 0.06 * 0.06),
              1e-15);
  EXPECT_EQ(PointNoiseSigma(o, Vec3(30.0, 0.0, 0.0), 0.0), 0.05);
  o.point_noise_angle = 0.004;
  EXPECT_NEAR(PointNoiseSigma(o, Vec3(0.0, 6.0, 8.0), 0.015),
              std::sqrt(0.05 * 0.05 + 0.04 * 0.04 + 0.03 * 0.03), 1e-15);
}

// A term that records the (whitened) association of every residual it is given.
class RecordingTerm final : public LidarTerm {
 public:
  explicit RecordingTerm(LidarTerm* inner) : inner_(inner) {}
  size_t num_keypoints() const override { return inner_->num_keypoints(); }
  void BeginRound() override { inner_->BeginRound(); }
  void Locate(size_t i, Vec3* q, Vec3* p_map) override { inner_->Locate(i, q, p_map); }
  ceres::ResidualBlockId AddResidual(size_t i, const PlaneAssociation& a, ceres::LossFunction* loss,
                                     SlidingWindow* window) override {
    last[i] = a;
    return inner_->AddResidual(i, a, loss, window);
  }
  void UpdateResidual(size_t i, const PlaneAssociation& a) override {
    last[i] = a;
    inner_->UpdateResidual(i, a);
  }
  SE3 NewestPose() const override { return inner_->NewestPose(); }
  std::map<size_t, PlaneAssociation> last;

 private:
  LidarTerm* inner_;
};

// In the registration each residual is whitened by its keypoint's own σ: the residual of a
// keypoint 10 m away weighs less than one 4 m away, by the ratio of their σ, while without the
// angle every keypoint has the configured σ; the room is registered either way. The summary
// reports each keypoint's σ (what the adaptive covariance whitens its residual by).
TEST(ScanRegistration, FarKeypointsAreWhitenedByTheirRangeDependentSigma) {
  const Scene s = MakeScene(44, 300);
  for (const double angle : {0.0, 0.005}) {
    LidarFrontendOptions o = Options(0.0);
    o.point_noise_sigma = 0.03;
    o.point_noise_angle = angle;
    SlidingWindow window(sweep::SweepWindowOptions(o));
    window.AddPoseState(0, s.T_rm_initial);
    sweep::RigidLidarTerm rigid(0, s.keypoints, window);
    RecordingTerm term(&rigid);
    const RegistrationSummary summary =
        ScanRegistration(o, OdometryConfig().min_associations).Register(s.map, &term, &window);
    ASSERT_FALSE(summary.degenerate);
    EXPECT_GT(summary.associations, 250);
    int near = 0, far = 0;
    ASSERT_EQ(summary.noise_sigma.size(), s.keypoints.size());
    for (size_t i = 0; i < s.keypoints.size(); ++i) {
      if (!summary.associated[i]) {
        EXPECT_EQ(summary.noise_sigma[i], 0.0) << i;
        continue;
      }
      const PlaneAssociation& whitened = term.last.at(i);
      const PlaneAssociation& plane = summary.planes[i];
      const double range = plane.point_robot.norm();
      const double sigma = std::sqrt(0.03 * 0.03 + angle * range * angle * range);
      EXPECT_NEAR(whitened.weight * sigma, plane.weight, 1e-12 * plane.weight) << i;
      EXPECT_NEAR(summary.noise_sigma[i], sigma, 1e-12 * sigma) << i;
      near += range < 5.0;
      far += range > 8.0;
    }
    EXPECT_GT(near, 10);
    EXPECT_GT(far, 10);
    EXPECT_LT(PoseDistance(window.Pose(0), s.T_rm_true),
              0.25 * PoseDistance(s.T_rm_initial, s.T_rm_true))
        << angle;
  }
}

}  // namespace
}  // namespace ctlio::lio
