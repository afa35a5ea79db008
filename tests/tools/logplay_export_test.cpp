// robotalk-logplay export (tools/logplay/export.h): state.csv's joint
// columns are named from the configuration the log holds (issue 21: they
// were one "q" column of unnamed values), joints.csv gives their units, and
// a robot whose configuration the log lacks is named q0.. and said so.
#include "export.h"
#include "robotalk/channels.h"
#include "robotalk/config_message.h"
#include "robotalk/request.h"
#include "robotalk/urdf_import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace robotalk::logplay {
namespace {

const char* kUrdf = R"(<robot name="rover">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="wheel"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="mast"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="wheel_joint" type="continuous"><parent link="base"/><child link="wheel"/><axis xyz="0 1 0"/></joint>
  <joint name="lift" type="prismatic"><parent link="base"/><child link="mast"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.5" effort="10" velocity="1"/></joint>
</robot>)";

std::vector<std::uint8_t> State(const std::string& robot, std::vector<double> q) {
  robotalk::StateSample s;
  s.server_time = TimePoint{std::chrono::seconds(1)};
  s.sample = 1;
  s.robot = robot;
  s.velocities.assign(q.size(), 0.0);
  s.efforts.assign(q.size(), 0.0);
  s.positions = std::move(q);
  return EncodeStateSample(s);
}

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class Export : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("logplay_export_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(Export, NamesTheStateColumnsFromTheLoggedConfiguration) {
  SessionLog log;
  LoggedConfigs configs;
  configs.Add(ConfigChannel("rover"), EncodeConfig(ParseUrdf(kUrdf, {}, "rover.urdf").model));
  log.Add(StateChannel("rover"), 10, State("rover", {45.5, 0.25}));
  std::ostringstream warnings;
  const auto files = ExportCsv(log, configs, dir_.string(), warnings);
  ASSERT_EQ(files.size(), 3u);
  const auto state = Lines(dir_ / "state.csv");
  ASSERT_EQ(state.size(), 2u);
  EXPECT_EQ(state[0], "robot,log_time_us,server_time_us,panic,moving,x,y,theta,v,omega,wheel_joint,lift");
  EXPECT_EQ(state[1], "rover,10,1000000,0,0,0,0,0,0,0,45.5,0.25");
  EXPECT_EQ(Lines(dir_ / "joints.csv"),
            (std::vector<std::string>{"robot,dof,column,unit,named_from", "rover,0,wheel_joint,rad,config",
                                      "rover,1,lift,m,config"}));
  EXPECT_EQ(warnings.str(), "");
}

TEST_F(Export, FallsBackToQNumbersAndSaysSoWithoutAConfiguration) {
  SessionLog log;
  LoggedConfigs configs;
  // A configuration of another size (the robot was restarted with another
  // model) does not name these dofs.
  configs.Add(ConfigChannel("rover"), EncodeConfig(ParseUrdf(kUrdf, {}, "rover.urdf").model));
  log.Add(StateChannel("rover"), 10, State("rover", {1, 2, 3}));
  std::ostringstream warnings;
  ExportCsv(log, configs, dir_.string(), warnings);
  EXPECT_EQ(Lines(dir_ / "state.csv")[0],
            "robot,log_time_us,server_time_us,panic,moving,x,y,theta,v,omega,q0,q1,q2");
  EXPECT_NE(warnings.str().find("no configuration (ROBOTALK/rover/CONFIG) of robot 'rover' with 3 dofs: its "
                                "joints are named q0..q2"),
            std::string::npos)
      << warnings.str();
  EXPECT_EQ(Lines(dir_ / "joints.csv")[1], "rover,0,q0,,none");
}

TEST_F(Export, GivesEachRobotItsOwnColumnsAndIgnoresABrokenConfiguration) {
  SessionLog log;
  LoggedConfigs configs;
  configs.Add(ConfigChannel("rover"), EncodeConfig(ParseUrdf(kUrdf, {}, "rover.urdf").model));
  configs.Add(ConfigChannel("other"), std::vector<std::uint8_t>{1, 2, 3});
  EXPECT_EQ(configs.undecodable(), 1u);
  log.Add(StateChannel("rover"), 10, State("rover", {1, 2}));
  log.Add(StateChannel("other"), 11, State("other", {7}));
  std::ostringstream warnings;
  ExportCsv(log, configs, dir_.string(), warnings);
  const auto state = Lines(dir_ / "state.csv");
  EXPECT_EQ(state[0], "robot,log_time_us,server_time_us,panic,moving,x,y,theta,v,omega,wheel_joint,lift,q0");
  EXPECT_EQ(state[1], "rover,10,1000000,0,0,0,0,0,0,0,1,2,");
  EXPECT_EQ(state[2], "other,11,1000000,0,0,0,0,0,0,0,,,7");
}

// Reproducer (failed before one number writer): the CSV wrote %.10g, so
// 1/3 came back as 0.3333333333 and 0.1 + 0.2 as 0.3: not the logged values.
TEST_F(Export, WritesEveryNumberSoItReadsBackToTheSameValue) {
  SessionLog log;
  LoggedConfigs configs;
  const double third = 1.0 / 3, sum = 0.1 + 0.2;
  log.Add(StateChannel("rover"), 10, State("rover", {third, sum}));
  std::ostringstream warnings;
  ExportCsv(log, configs, dir_.string(), warnings);
  const std::string row = Lines(dir_ / "state.csv")[1];
  ASSERT_EQ(std::count(row.begin(), row.end(), ','), 11) << row;
  const std::string cells = row.substr(row.rfind(',', row.rfind(',') - 1) + 1);
  const std::size_t comma = cells.find(',');
  EXPECT_EQ(std::strtod(cells.substr(0, comma).c_str(), nullptr), third) << row;
  EXPECT_EQ(std::strtod(cells.substr(comma + 1).c_str(), nullptr), sum) << row;
  EXPECT_EQ(cells, "0.3333333333333333,0.30000000000000004");  // and the shortest such text
}

}  // namespace
}  // namespace robotalk::logplay
