// The scoreboard's pooling of ctlio_experiment cells (apps/lio/scoreboard.h): the RMS over runs, a
// diverged run that must show in the ATE, the winners, the target, the labels read back from a
// cell folder, and the refusals (a method or a sequence missing).
#include "lio/scoreboard.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "ctlio/io/checked_output.h"

namespace ctlio::lioapp {
namespace {

RunRow MakeRun(const std::string& method, int sequence, double ate, double cpu_ms, int failed = 0) {
  RunRow r;
  r.regime = "walking";
  r.sequence = sequence;
  r.method = method;
  r.ate_rmse_m = ate;
  r.ate_pairs = 100;
  r.failed_scans = failed;
  r.failure = failed > 0 || ate > 1.0;
  r.median_cpu_ms = cpu_ms;
  r.p95_cpu_ms = 2 * cpu_ms;
  r.drift_m_per_100m = 10 * ate;
  r.scans = 100;
  return r;
}

ScoreboardCellRuns Cell(std::vector<RunRow> rows) {
  ScoreboardCellRuns c;
  c.sensor = "vlp16";
  c.world = "park";
  c.duration_s = 20;
  c.rows = std::move(rows);
  return c;
}

TEST(Scoreboard, AteIsTheRmsOverRunsAndCpuTheMedianOverRuns) {
  const auto rows =
      ScoreCells({Cell({MakeRun("singer_lio", 0, 0.03, 8), MakeRun("imu_input", 0, 0.02, 20),
                        MakeRun("singer_lio", 1, 0.04, 10), MakeRun("imu_input", 1, 0.02, 30),
                        MakeRun("singer_lio", 2, 0.00, 9), MakeRun("imu_input", 2, 0.02, 25)})});
  ASSERT_EQ(rows.size(), 1u);
  const ScoreboardRow& r = rows[0];
  EXPECT_EQ(r.sensor, "vlp16");
  EXPECT_EQ(r.world, "park");
  EXPECT_EQ(r.regime, "walking");
  EXPECT_EQ(r.sequences, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(r.singer.runs, 3);
  // sqrt((0.03² + 0.04² + 0²) / 3), not the mean (0.0233) nor the pooled-over-runs-with-ATE RMS
  // that would skip the perfect run.
  EXPECT_NEAR(r.singer.ate_rms_m, std::sqrt(0.0025 / 3), 1e-12);
  EXPECT_NEAR(r.baseline.ate_rms_m, 0.02, 1e-12);
  EXPECT_DOUBLE_EQ(r.singer.cpu_median_ms, 9.0);
  EXPECT_DOUBLE_EQ(r.baseline.cpu_median_ms, 25.0);
  EXPECT_DOUBLE_EQ(r.singer.cpu_p95_ms, 18.0);
  EXPECT_NEAR(r.cpu_ratio, 9.0 / 25.0, 1e-12);
  EXPECT_EQ(r.ate_winner, "imu_input");  // 2.89 cm against 2 cm
  EXPECT_EQ(r.cpu_winner, "singer_lio");
  EXPECT_FALSE(r.target_met);
}

TEST(Scoreboard, ADivergedRunShowsInTheAteAndFailsTheTarget) {
  // The baseline diverges on one of two runs: its ATE must not hide it (drift only over the
  // non-failed run), and Singer-LIO's one failed scan keeps its target unmet although it wins.
  const auto rows =
      ScoreCells({Cell({MakeRun("singer_lio", 0, 0.01, 8, 1), MakeRun("imu_input", 0, 0.01, 9),
                        MakeRun("singer_lio", 1, 0.01, 8), MakeRun("imu_input", 1, 66.0, 9)})});
  const ScoreboardRow& r = rows.at(0);
  EXPECT_NEAR(r.baseline.ate_rms_m, std::sqrt((0.01 * 0.01 + 66.0 * 66.0) / 2), 1e-9);
  EXPECT_EQ(r.baseline.failed_runs, 1);
  EXPECT_NEAR(r.baseline.drift_m_per_100m, 0.1, 1e-12);
  EXPECT_EQ(r.singer.failed_runs, 1);
  EXPECT_EQ(r.singer.failed_scans, 1);
  EXPECT_EQ(r.ate_winner, "singer_lio");
  EXPECT_EQ(r.cpu_winner, "singer_lio");
  EXPECT_FALSE(r.target_met);
  const std::string summary = ScoreboardSummary(rows);
  EXPECT_NE(summary.find("Target met"), std::string::npos);
  EXPECT_NE(summary.find("in 0 of 1 cells"), std::string::npos) << summary;
}

TEST(Scoreboard, TiesWithinThePrintedDigitsCountForSingerLio) {
  const auto rows = ScoreCells(
      {Cell({MakeRun("singer_lio", 0, 0.020004, 10.02), MakeRun("imu_input", 0, 0.02, 10.0)})});
  EXPECT_EQ(rows.at(0).ate_winner, "tie");
  EXPECT_EQ(rows.at(0).cpu_winner, "tie");
  EXPECT_TRUE(rows.at(0).target_met);
  EXPECT_NE(ScoreboardMarkdown(rows).find("| met |"), std::string::npos);
}

TEST(Scoreboard, RefusesAMissingMethodOrUnequalSequences) {
  EXPECT_THROW(ScoreCells({Cell({MakeRun("singer_lio", 0, 0.01, 8)})}), std::runtime_error);
  try {
    ScoreCells({Cell({MakeRun("singer_lio", 0, 0.01, 8), MakeRun("imu_input", 1, 0.01, 9)})});
    FAIL() << "unequal sequences accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("vlp16/park/walking"), std::string::npos) << e.what();
  }
}

TEST(Scoreboard, ReadsACellFolderAndLabelsItBySensorOrConfig) {
  const std::string dir = testing::TempDir() + "/scoreboard_cell";
  std::filesystem::create_directories(dir);
  WriteResultsCsv(dir + "/results.csv",
                  {MakeRun("singer_lio", 0, 0.01, 8), MakeRun("imu_input", 0, 0.02, 9)});
  io::WriteTextFile(dir + "/settings.txt",
                    "preset none\nworld office\nduration_s 20\nconfig os0_128.yaml\n");
  ScoreboardCellRuns c = ReadScoreboardCell(dir);
  EXPECT_EQ(c.sensor, "os0_128");  // from the shipped config's name
  EXPECT_EQ(c.world, "office");
  EXPECT_EQ(c.duration_s, 20.0);
  EXPECT_EQ(c.rows.size(), 2u);
  io::WriteTextFile(dir + "/settings.txt",
                    "world office\nduration_s 20\nconfig mine.yaml\nsensor avia\n");
  EXPECT_EQ(ReadScoreboardCell(dir).sensor, "avia");  // the settings' sensor line wins
  const std::string csv = dir + "/scoreboard.csv";
  WriteScoreboardCsv(csv, ScoreCells({ReadScoreboardCell(dir)}));
  std::ifstream f(csv);
  std::string header, line;
  std::getline(f, header);
  std::getline(f, line);
  EXPECT_EQ(line.rfind("avia,office,walking,1,0.01,", 0), 0u) << line;
  EXPECT_NE(line.find(",singer_lio,singer_lio,1"), std::string::npos) << line;
  std::filesystem::remove(dir + "/settings.txt");
  EXPECT_THROW(ReadScoreboardCell(dir), std::runtime_error);
}

}  // namespace
}  // namespace ctlio::lioapp
