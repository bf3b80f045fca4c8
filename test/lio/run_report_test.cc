// What ctlio_odometry and ctlio_experiment say around their results: the list of the files
// written (apps/lio/output_files.h), the progress on a terminal and redirected
// (apps/lio/progress.h), and which config a run uses (apps/lio/config_origin.h).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "common/test_paths.h"
#include "lio/config_origin.h"
#include "lio/output_files.h"
#include "lio/progress.h"

namespace ctlio::lioapp {
namespace {

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(OutputFiles, ListsEveryFileOncePerLineInTheOrderRegistered) {
  OutputFiles files;
  files.Add("/out/trajectory.tum", "poses");
  files.Add("/out/evaluation.txt", "first description");
  files.Add("/out/a.csv", "errors");
  files.Add("/out/evaluation.txt", "summary");  // again: keeps its place, new description
  std::ostringstream os;
  files.Print(os);
  const std::vector<std::string> lines = Lines(os.str());
  ASSERT_EQ(lines.size(), 4u) << os.str();
  EXPECT_EQ(lines[0], "Files written:");
  // Paths padded to the longest, so that the descriptions line up.
  EXPECT_EQ(lines[1], "  /out/trajectory.tum  poses");
  EXPECT_EQ(lines[2], "  /out/evaluation.txt  summary");
  EXPECT_EQ(lines[3], "  /out/a.csv           errors");
  EXPECT_EQ(files.entries().size(), 3u);
}

TEST(OutputFiles, PrintsNothingWithoutFiles) {
  std::ostringstream os;
  OutputFiles().Print(os);
  EXPECT_EQ(os.str(), "");
}

// Redirected: no '\r', a line at every tenth of the total or after the interval, and the last.
TEST(ProgressReporter, RedirectedWritesWholeLinesAtTenthsAndIntervals) {
  double now = 0.0;
  std::ostringstream os;
  ProgressReporter progress(os, /*terminal=*/false, /*interval_s=*/5.0, [&] { return now; });
  for (size_t done = 1; done <= 200; ++done) {
    now += 0.01;  // 2 s in all: the interval never passes, only the tenths print
    progress.Update(done, 200, "scan " + std::to_string(done));
  }
  progress.Finish();
  EXPECT_EQ(os.str().find('\r'), std::string::npos);
  const std::vector<std::string> lines = Lines(os.str());
  ASSERT_EQ(lines.size(), 10u) << os.str();
  EXPECT_EQ(lines.front(), "scan 20");
  EXPECT_EQ(lines[4], "scan 100");
  EXPECT_EQ(lines.back(), "scan 200");
  EXPECT_EQ(os.str().back(), '\n');
}

TEST(ProgressReporter, RedirectedWithUnknownTotalPrintsEveryIntervalAndTheLastAtFinish) {
  double now = 0.0;
  std::ostringstream os;
  ProgressReporter progress(os, false, 5.0, [&] { return now; });
  for (size_t done = 1; done <= 23; ++done) {
    now += 1.0;  // a line at 5, 10, 15 and 20 s
    progress.Update(done, 0, "scan " + std::to_string(done));
  }
  progress.Event("  degenerate at t = 2.300 s: few associations");
  progress.Finish();
  EXPECT_EQ(Lines(os.str()),
            (std::vector<std::string>{"scan 5", "scan 10", "scan 15", "scan 20",
                                      "  degenerate at t = 2.300 s: few associations", "scan 23"}));
}

TEST(ProgressReporter, TerminalRewritesOneLineAndEndsItBeforeAnEvent) {
  std::ostringstream os;
  ProgressReporter progress(os, /*terminal=*/true);
  progress.Update(1, 3, "scan 1");
  progress.Update(2, 3, "scan 2");
  progress.Event("  failed at t = 0.200 s: diverged");
  progress.Update(3, 3, "scan 3");
  progress.Finish();
  EXPECT_EQ(os.str(), "\rscan 1   \rscan 2   \n  failed at t = 0.200 s: diverged\n\rscan 3   \n");
}

TEST(ProgressReporter, ShowsAtMostTheEventLimitAndCountsTheRest) {
  double now = 0.0;
  std::ostringstream os;
  ProgressReporter progress(os, false, 5.0, [&] { return now; });
  progress.SetEventLimit(2, "scans.log has every scan");
  for (int i = 0; i < 5; ++i) progress.Event("degenerate " + std::to_string(i));
  progress.Update(1, 1, "scan 1/1");
  progress.Finish();
  EXPECT_EQ(Lines(os.str()), (std::vector<std::string>{
                                 "degenerate 0", "degenerate 1", "scan 1/1",
                                 "  (3 more such lines not shown; scans.log has every scan)"}));
}

TEST(ConfigOrigin, SaysWhenTheBuiltInDefaultsApply) {
  EXPECT_EQ(DescribeConfig(""), "built-in defaults (no --config)");
}

TEST(ConfigOrigin, NamesEveryFileOfTheComposition) {
  const std::string dir = testing::FreshTempDir("config_origin").string();
  std::ofstream(dir + "/c.yaml") << "imu: {gravity: 9.81}\n";
  std::ofstream(dir + "/b.yaml") << "base: c.yaml\n";
  std::ofstream(dir + "/a.yaml") << "base: " << dir << "/b.yaml\n";  // absolute works as well
  std::ofstream(dir + "/plain.yaml") << "lidar_frontend: {point_noise_sigma: 0.02}\n";
  std::ofstream(dir + "/bad.yaml") << "no_such_section: 1\n";
  EXPECT_EQ(DescribeConfig(dir + "/plain.yaml"), dir + "/plain.yaml");
  EXPECT_EQ(DescribeConfig(dir + "/a.yaml"), dir + "/c.yaml (base of " + dir + "/b.yaml), " + dir +
                                                 "/b.yaml (base of " + dir + "/a.yaml), " + dir +
                                                 "/a.yaml; later files win key by key");
  // A list on the command line: every file, in the order applied.
  EXPECT_EQ(DescribeConfig(dir + "/plain.yaml," + dir + "/b.yaml"),
            dir + "/plain.yaml, " + dir + "/c.yaml (base of " + dir + "/b.yaml), " + dir +
                "/b.yaml; later files win key by key");
  // A config that does not load (its error is the loader's to report): as given.
  EXPECT_EQ(DescribeConfig(dir + "/bad.yaml"), dir + "/bad.yaml");
  // The repository's calibration config: the simulator config and the calibration overlay.
  const std::string data = ctlio::testing::SourceDir() + "/data/";
  EXPECT_EQ(DescribeConfig(data + "sim_lio_calibration.yaml"),
            data + "sim_lio.yaml (base of " + data + "sim_lio_calibration.yaml), " + data +
                "calibration.yaml (base of " + data + "sim_lio_calibration.yaml), " + data +
                "sim_lio_calibration.yaml; later files win key by key");
}

}  // namespace
}  // namespace ctlio::lioapp
