// One settings table per stage feeds both front doors: every command-line option of interpolate,
// segment, mesh and solve is a case-file key of that stage with the same name and default, and
// every key an option; both take the same values and refuse the same bad ones.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <string>
#include <vector>

#include "app/stage_settings.h"
#include "core/error.h"

namespace naris::app {
namespace {

// The stage's options on a fresh command line, minus help, the positional input and -o.
std::vector<const CLI::Option*> stage_options(const CLI::App& cmd) {
  std::vector<const CLI::Option*> out;
  for (const CLI::Option* o : cmd.get_options()) {
    if (o->get_name() == "--help" || o->get_name() == "-h" || o->get_positional()) continue;
    if (o->check_lname("output")) continue;
    out.push_back(o);
  }
  return out;
}

template <class Stage>
void expect_one_table(const char* stage) {
  Stage s;
  CLI::App app;
  CLI::App* cmd = app.add_subcommand(stage, "");
  cmd->add_option("input", s.job.output);  // stands for the positional input
  cmd->add_option("-o,--output", s.job.output);
  s.table.add_to(cmd);
  // Every key an option of the same name and default …
  for (const Settings::Entry& e : s.table.entries()) {
    const std::string flag = Settings::option_name(e);
    const CLI::Option* o = cmd->get_option_no_throw(flag);
    ASSERT_NE(o, nullptr) << stage << ": " << e.name << " has no option " << flag;
    if (e.kind != Settings::Kind::flag) {
      EXPECT_EQ(o->get_default_str(), e.default_text) << stage << " " << flag;
    }
    std::string dashed = e.name;
    std::replace(dashed.begin(), dashed.end(), '_', '-');
    EXPECT_NE(flag.find(dashed), std::string::npos) << flag;
  }
  // … and every option a key.
  const auto options = stage_options(*cmd);
  EXPECT_EQ(options.size(), s.table.entries().size()) << stage;
  for (const CLI::Option* o : options) {
    const auto found = std::find_if(
        s.table.entries().begin(), s.table.entries().end(),
        [&](const Settings::Entry& e) { return o->check_name(Settings::option_name(e)); });
    EXPECT_NE(found, s.table.entries().end())
        << stage << ": option " << o->get_name() << " is no case-file key";
  }
}

TEST(StageSettings, EveryOptionIsACaseFileKeyWithTheSameDefault) {
  expect_one_table<InterpolateSettings>("interpolate");
  expect_one_table<SegmentSettings>("segment");
  expect_one_table<MeshSettings>("mesh");
  expect_one_table<SolveSettings>("solve");
}

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

TEST(StageSettings, TheLibrarysDefaultsAreTheTablesDefaults) {
  const SolveSettings solve;
  const airflow::AirflowJob job = solve.resolve();
  const airflow::AirflowJob library;
  EXPECT_EQ(job.reynolds, library.reynolds);
  EXPECT_EQ(job.nonlinear.pseudo_cfl, library.nonlinear.pseudo_cfl);
  EXPECT_EQ(job.nonlinear.max_iterations, library.nonlinear.max_iterations);
  EXPECT_EQ(job.nonlinear.reuse_preconditioner, library.nonlinear.reuse_preconditioner);
  EXPECT_EQ(job.start_reynolds, library.start_reynolds);
  const MeshSettings mesh;
  EXPECT_EQ(mesh.resolve().improve, MeshJob{}.improve);
  EXPECT_EQ(mesh.resolve().keep_largest, MeshJob{}.keep_largest);
  EXPECT_EQ(mesh.resolve().inside, MeshJob{}.inside);
  const SegmentSettings segment;
  EXPECT_EQ(segment.resolve().threshold, SegmentJob{}.threshold);
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
