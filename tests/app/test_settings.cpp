// One settings table per stage feeds both front doors: both take the same values and refuse the
// same bad ones (that the binary's options are exactly the tables' entries, with their defaults,
// is Cli.EveryStageOptionIsACaseFileKeyWithTheSameDefault).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <string>
#include <vector>

#include "app/stage_settings.h"
#include "core/error.h"

namespace naris::app {
namespace {

// A case-file section that sets every key to its default is accepted, and so is the command
// line that gives every option its default.
template <class Stage>
void expect_defaults_accepted(const char* stage) {
  Stage s;
  YAML::Node section(YAML::NodeType::Map);
  std::vector<std::string> args = {"naris", stage};
  for (const Settings::Entry& e : s.table.entries()) {
    if (e.default_text.empty()) continue;  // unset by default
    section[e.name] = e.default_text;
    if (e.kind == Settings::Kind::flag) continue;  // a flag's default is its absence
    args.push_back(Settings::option_name(e));
    args.push_back(e.default_text);
  }
  EXPECT_NO_THROW(s.table.read(section, stage)) << YAML::Dump(section);
  Stage t;
  CLI::App app;
  CLI::App* cmd = app.add_subcommand(stage, "");
  t.table.add_to(cmd);
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  EXPECT_NO_THROW(app.parse(static_cast<int>(argv.size()), argv.data())) << stage;
}

TEST(StageSettings, DefaultsAreAcceptedByBothFrontDoors) {
  expect_defaults_accepted<InterpolateSettings>("interpolate");
  expect_defaults_accepted<SegmentSettings>("segment");
  expect_defaults_accepted<MeshSettings>("mesh");
  expect_defaults_accepted<SolveSettings>("solve");
}

// The defaults the commands had before one table fed both doors (the command line's
// pseudo-time at 5, where the library had 0) are the library's now, and nothing given resolves to
// them.
TEST(StageSettings, NothingGivenResolvesToTheDocumentedDefaults) {
  const airflow::AirflowJob solve = SolveSettings().resolve();
  EXPECT_EQ(solve.reynolds, 610.0);
  EXPECT_EQ(solve.nonlinear.pseudo_cfl, 5.0);
  EXPECT_EQ(airflow::AirflowJob{}.nonlinear.pseudo_cfl, 5.0);
  EXPECT_EQ(solve.start_reynolds, 50.0);
  EXPECT_EQ(solve.max_steps, 40);
  EXPECT_EQ(solve.nonlinear.max_iterations, 50);
  EXPECT_EQ(solve.nonlinear.tolerance, 1e-8);
  EXPECT_EQ(solve.step_tolerance, 1e-5);
  EXPECT_EQ(solve.arclength_steps, 30);
  EXPECT_TRUE(solve.nonlinear.newton);
  EXPECT_TRUE(solve.nonlinear.reuse_preconditioner);
  EXPECT_FALSE(solve.nonlinear.log_iterations);
  EXPECT_EQ(solve.profile, ns::InletProfile::uniform);
  EXPECT_FALSE(solve.inlet_speed.has_value());
  EXPECT_FALSE(solve.restart.has_value());
  const MeshJob mesh = MeshSettings().resolve();
  EXPECT_TRUE(mesh.improve);
  EXPECT_TRUE(mesh.keep_largest);
  EXPECT_TRUE(mesh.check);
  EXPECT_TRUE(mesh.write_msh);
  EXPECT_EQ(mesh.inside, InsideRule::below);
  EXPECT_EQ(mesh.improve_options.min_edge_fraction, 0.2);
  EXPECT_FALSE(mesh.threshold.has_value());
  EXPECT_FALSE(mesh.label.has_value());
  const SegmentJob segment = SegmentSettings().resolve();
  EXPECT_EQ(segment.threshold, "auto");
  EXPECT_EQ(segment.inside, InsideRule::below);
  EXPECT_TRUE(segment.seeds.empty());
  EXPECT_EQ(segment.decimate, 1);
  const InterpolateJob interpolate = InterpolateSettings().resolve();
  EXPECT_EQ(interpolate.method, SliceMethod::hsr);
  EXPECT_EQ(interpolate.axis, "auto");
  EXPECT_FALSE(interpolate.insert.has_value());
  EXPECT_FALSE(interpolate.spacing.has_value());
}

TEST(StageSettings, NullInACaseFileIsNotGiven) {
  SolveSettings s;
  s.table.read(YAML::Load("{scheme: segregated, max_iterations: ~}"), "solve");
  EXPECT_FALSE(s.table.given("max_iterations"));
  EXPECT_EQ(s.resolve().nonlinear.max_iterations, 500);
  MeshSettings m;
  m.table.read(YAML::Load("{threshold: ~, label: 1}"), "mesh");
  EXPECT_NO_THROW((void)m.resolve());
}

TEST(StageSettings, YamlBooleansInEverySpelling) {
  for (const char* off : {"false", "no", "off", "False", "NO"}) {
    MeshSettings m;
    m.table.read(YAML::Load(std::string("{improve: ") + off + "}"), "mesh");
    EXPECT_FALSE(m.resolve().improve) << off;
  }
  MeshSettings m;
  EXPECT_THROW(m.table.read(YAML::Load("{improve: maybe}"), "mesh"), Error);
}

TEST(StageSettings, ListsTakeSeveralValuesAndScalarsOne) {
  SegmentSettings s;
  CLI::App app;
  CLI::App* cmd = app.add_subcommand("segment", "");
  s.table.add_to(cmd);
  const char* argv[] = {"naris", "segment", "--seed", "1,2,3", "4,5,6", "--seed", "7,8,9"};
  app.parse(7, argv);
  EXPECT_EQ(s.job.seeds, (std::vector<std::string>{"1,2,3", "4,5,6", "7,8,9"}));
  MeshSettings m;
  CLI::App app2;
  CLI::App* mesh = app2.add_subcommand("mesh", "");
  m.table.add_to(mesh);
  const char* twice[] = {"naris", "mesh", "--min-edge", "0.1", "--min-edge", "0.2"};
  EXPECT_THROW(app2.parse(6, twice), CLI::ParseError);
}

TEST(StageSettings, BothFrontDoorsRefuseTheSameBadValues) {
  for (const auto& [key, value, message] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"min_edge", "0.7", "outside"},
           {"subdivide", "two", "not a whole number"},
           {"inside", "left", "not one of"}}) {
    MeshSettings yaml_side, cli_side;
    YAML::Node section(YAML::NodeType::Map);
    section[key] = value;
    try {
      yaml_side.table.read(section, "case.yaml: mesh");
      ADD_FAILURE() << key << " " << value << " accepted in a case file";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("case.yaml: mesh." + key), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
    CLI::App app;
    CLI::App* cmd = app.add_subcommand("mesh", "");
    cli_side.table.add_to(cmd);
    std::string dashed = key;
    std::replace(dashed.begin(), dashed.end(), '_', '-');
    const std::string flag = "--" + dashed;
    const char* argv[] = {"naris", "mesh", flag.c_str(), value.c_str()};
    try {
      app.parse(4, argv);
      ADD_FAILURE() << key << " " << value << " accepted on the command line";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(flag), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

TEST(StageSettings, UnknownKeysAndListsWhereOneValueIsExpectedAreErrors) {
  MeshSettings s;
  EXPECT_THROW(s.table.read(YAML::Load("{improv: false}"), "mesh"), Error);
  EXPECT_THROW(s.table.read(YAML::Load("{min_edge: [0.1, 0.2]}"), "mesh"), Error);
  EXPECT_NO_THROW(
      s.table.read(YAML::Load("{patch: [\"a:sphere=0,0,0,1\", \"b:sphere=1,1,1,1\"]}"), "mesh"));
  EXPECT_EQ(s.job.regions.size(), 2u);
  EXPECT_TRUE(s.table.given("patch"));
  EXPECT_FALSE(s.table.given("inlet"));
}

TEST(StageSettings, ConflictingSettingsAreRefusedWhereverGiven) {
  MeshSettings s;
  s.table.read(YAML::Load("{threshold: 0.5, label: 1}"), "mesh");
  EXPECT_THROW((void)s.resolve(), Error);
  SolveSettings t;
  t.table.read(YAML::Load("{restart_mesh: coarse.h5}"), "solve");
  EXPECT_THROW((void)t.resolve(), Error);
}

TEST(StageSettings, SegregatedSchemeTakes500IterationsUnlessGiven) {
  SolveSettings s;
  s.table.read(YAML::Load("{scheme: segregated}"), "solve");
  EXPECT_EQ(s.resolve().nonlinear.max_iterations, 500);
  SolveSettings t;
  t.table.read(YAML::Load("{scheme: segregated, max_iterations: 50}"), "solve");
  EXPECT_EQ(t.resolve().nonlinear.max_iterations, 50);
}

TEST(StageSettings, CaseFilePathsAreRelativeToTheCaseFile) {
  SolveSettings s;
  s.table.read(YAML::Load("{restart: run/checkpoint.h5}"), "solve");
  EXPECT_EQ(s.resolve("/cases/a").restart->string(), "/cases/a/run/checkpoint.h5");
}

}  // namespace
}  // namespace naris::app
