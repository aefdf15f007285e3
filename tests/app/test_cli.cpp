// The command line against bad input: each case must print one line `naris: error: ...` that
// names the problem, exit non-zero, and leave no output file behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <sstream>
#include <vector>

#include "app/stage_settings.h"
#include "core/hdf5_table.h"
#include "solver/airflow/solution_file.h"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;
  std::string err;
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("naris-cli-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "in");
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `launcher` runs the binary (mpiexec …) when given.
  CliRun naris(const std::string& args, const std::string& launcher = "") {
    const fs::path err = dir_ / "stderr.txt";
    const std::string cmd =
        launcher + std::string(NARIS_BINARY) + " " + args + " 2> " + err.string() + " > /dev/null";
    CliRun r;
    const int raw = std::system(cmd.c_str());
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    std::ifstream in(err);
    r.err.assign((std::istreambuf_iterator<char>(in)), {});
    return r;
  }

  // A little NRRD with a raw payload; `bytes` may be shorter than the header promises.
  fs::path nrrd(const std::string& name, const std::string& type, const std::string& sizes,
                const std::string& bytes, int dimension = 3) {
    const fs::path p = dir_ / "in" / name;
    std::ofstream out(p, std::ios::binary);
    out << "NRRD0004\ntype: " << type << "\ndimension: " << dimension << "\nsizes: " << sizes
        << "\nencoding: raw\nendian: little\n\n"
        << bytes;
    return p;
  }

  template <class T>
  static std::string payload(const std::vector<T>& v) {
    return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }

  // A 12³ ball of radius 4 as 0/1 labels.
  static std::vector<std::uint8_t> ball_labels() {
    std::vector<std::uint8_t> v(12 * 12 * 12);
    for (int k = 0; k < 12; ++k)
      for (int j = 0; j < 12; ++j)
        for (int i = 0; i < 12; ++i)
          v[static_cast<std::size_t>(i + 12 * (j + 12 * k))] =
              std::hypot(i - 5.5, j - 5.7, k - 5.6) < 4.0 ? 1 : 0;
    return v;
  }

  void expect_clean_failure(const CliRun& r, const std::string& needle) {
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(r.err.rfind("naris: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << "expected '" << needle << "' in: " << r.err;
    const fs::path out = dir_ / "out";
    if (fs::exists(out))
      for (const auto& e : fs::recursive_directory_iterator(out))
        ADD_FAILURE() << "left a file behind: " << e.path();
  }

  std::string out() const { return "-o " + (dir_ / "out" / "mesh.h5").string(); }

  // The solver tests' case: the 12³ ball meshed into `mesh` with an inlet at k = 3 and an
  // outlet at k = 8.
  void mesh_cut_ball(const fs::path& mesh) {
    const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
    const CliRun r = naris("mesh " + in.string() + " --inlet k=3 --outlet k=8 -o " + mesh.string());
    ASSERT_EQ(r.status, 0) << r.err;
  }

  // A number from the summary.json in `folder` (six significant digits).
  static double summary(const fs::path& folder, const std::string& key) {
    std::ifstream file(folder / "summary.json");
    const std::string text((std::istreambuf_iterator<char>(file)), {});
    std::smatch m;
    const std::regex number("\"" + key + "\": ([-0-9.e+]+)");
    if (!std::regex_search(text, m, number)) ADD_FAILURE() << key << " missing in " << folder;
    return m.empty() ? NAN : std::stod(m[1]);
  }

  fs::path dir_;
};

TEST_F(Cli, MeshesABallAndWritesEveryFile) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const CliRun r = naris("mesh " + in.string() + " " + out());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f :
       {"mesh.h5", "mesh.xdmf", "mesh.vtu", "boundary.vtp", "surface.stl", "mesh.msh", "mesh.json"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / f)) << f;
  EXPECT_NE(r.err.find("conforming, watertight"), std::string::npos) << r.err;
}

// Subdivision refines the mesh without moving its boundary: the inlet keeps its area and
// perimeter (so the solver's d_in and U_in), the volume stays, the cells grow 8–10×.
TEST_F(Cli, SubdivideRefinesTheSameGeometry) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  auto mesh_json = [](const fs::path& folder) {
    std::ifstream file(folder / "mesh.json");
    return nlohmann::json::parse(file);
  };
  auto inlet = [](const nlohmann::json& j, const char* key) -> double {
    for (const auto& p : j["patches"])
      if (p["name"] == "inlet") return p[key].get<double>();
    ADD_FAILURE() << "no inlet patch in " << j.dump();
    return NAN;
  };
  const fs::path coarse = dir_ / "coarse", fine = dir_ / "fine";
  ASSERT_EQ(
      naris("mesh " + in.string() + " --inlet k=3 --outlet k=8 -o " + (coarse / "mesh.h5").string())
          .status,
      0);
  const CliRun r = naris("mesh " + in.string() + " --inlet k=3 --outlet k=8 --subdivide 1 -o " +
                         (fine / "mesh.h5").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("subdivided 1×"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("conforming, watertight"), std::string::npos) << r.err;
  const nlohmann::json a = mesh_json(coarse), b = mesh_json(fine);
  EXPECT_GE(b["cells"]["tet"].get<double>(), 8 * a["cells"]["tet"].get<double>());
  const double volume = a["volume_mm3"].get<double>();
  EXPECT_NEAR(b["volume_mm3"].get<double>(), volume, 1e-5 * volume);
  EXPECT_NEAR(inlet(b, "area_mm2"), inlet(a, "area_mm2"), 1e-5 * inlet(a, "area_mm2"));
  EXPECT_NEAR(inlet(b, "perimeter_mm"), inlet(a, "perimeter_mm"), 1e-5 * inlet(a, "perimeter_mm"));
  expect_clean_failure(naris("mesh " + in.string() + " --subdivide 5 " + out()), "--subdivide");
}

TEST_F(Cli, QuietPrintsNothing) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const CliRun r = naris("--quiet mesh " + in.string() + " " + out());
  ASSERT_EQ(r.status, 0);
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(Cli, MissingFile) {
  expect_clean_failure(naris("mesh " + (dir_ / "in" / "absent.nrrd").string() + " " + out()),
                       "absent.nrrd: no such file");
}

TEST_F(Cli, TruncatedFile) {
  const std::string bytes = payload(ball_labels());
  const fs::path in = nrrd("cut.nrrd", "uint8", "12 12 12", bytes.substr(0, bytes.size() / 3));
  expect_clean_failure(naris("mesh " + in.string() + " " + out()), "cut.nrrd");
}

TEST_F(Cli, CorruptFile) {
  const fs::path p = dir_ / "in" / "junk.nrrd";
  std::ofstream(p) << "this is not an image\x01\x02";
  expect_clean_failure(naris("mesh " + p.string() + " " + out()), "junk.nrrd");
}

TEST_F(Cli, UnsupportedPixelType) {
  std::vector<std::uint8_t> rgb(3 * 12 * 12 * 12, 7);
  const fs::path in = nrrd("rgb.nrrd", "uint8", "3 12 12 12", payload(rgb), 4);
  expect_clean_failure(naris("mesh " + in.string() + " " + out()), "rgb.nrrd");
}

TEST_F(Cli, EmptySegmentation) {
  const fs::path in = nrrd("empty.nrrd", "uint8", "12 12 12", std::string(12 * 12 * 12, '\0'));
  expect_clean_failure(naris("mesh " + in.string() + " --label 1 " + out()), "empty segmentation");
}

TEST_F(Cli, EverythingInside) {
  const fs::path in = nrrd("full.nrrd", "uint8", "12 12 12", std::string(12 * 12 * 12, '\1'));
  expect_clean_failure(naris("mesh " + in.string() + " --label 1 " + out()),
                       "every voxel is inside");
}

TEST_F(Cli, NanValues) {
  std::vector<float> v(12 * 12 * 12, 1.0f);
  v[100] = std::numeric_limits<float>::quiet_NaN();
  const fs::path in = nrrd("nan.nrrd", "float", "12 12 12", payload(v));
  expect_clean_failure(naris("mesh " + in.string() + " --threshold 0.5 " + out()), "NaN");
}

TEST_F(Cli, ThresholdOutsideTheDataRange) {
  std::vector<float> v(12 * 12 * 12);
  for (std::size_t n = 0; n < v.size(); ++n) v[n] = static_cast<float>(n % 7);
  const fs::path in = nrrd("ct.nrrd", "float", "12 12 12", payload(v));
  expect_clean_failure(naris("mesh " + in.string() + " --threshold 500 " + out()),
                       "outside the data range");
}

TEST_F(Cli, InletPlaneThatDoesNotCutTheObject) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  expect_clean_failure(naris("mesh " + in.string() + " --inlet k=1 " + out()), "does not cut");
}

TEST_F(Cli, BadPlaneSyntax) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  expect_clean_failure(naris("mesh " + in.string() + " --inlet q=3 " + out()), "not understood");
}

TEST_F(Cli, OutputFolderNotWritable) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const CliRun r = naris("mesh " + in.string() + " -o /proc/naris-test/mesh.h5");
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(r.err.rfind("naris: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("/proc/naris-test"), std::string::npos) << r.err;
}

// Each stage that a case file also runs offers on the command line exactly its settings table's
// entries, with the table's defaults: read from the binary's own --help.
TEST_F(Cli, EveryStageOptionIsACaseFileKeyWithTheSameDefault) {
  auto check = [&](const std::string& stage, const naris::app::Settings& table) {
    const fs::path text = dir_ / (stage + "-help.txt");
    ASSERT_EQ(std::system(
                  (std::string(NARIS_BINARY) + " " + stage + " --help > " + text.string()).c_str()),
              0);
    std::ifstream in(text);
    std::map<std::string, std::string> listed;  // option → its shown default
    const std::regex option(R"(^\s+(?:-\w,)?(--[a-z][a-z0-9-]*)(?: [A-Z]+)?(?:=(\S+))?)");
    for (std::string line; std::getline(in, line);) {
      std::smatch m;
      if (std::regex_search(line, m, option)) listed[m[1]] = m[2];
    }
    listed.erase("--help");
    listed.erase("--output");
    EXPECT_EQ(listed.size(), table.entries().size()) << stage;
    for (const auto& e : table.entries()) {
      const auto it = listed.find(naris::app::Settings::option_name(e));
      ASSERT_NE(it, listed.end()) << stage << ": the case-file key " << e.name << " is no option";
      if (e.kind != naris::app::Settings::Kind::flag) {
        EXPECT_EQ(it->second, e.default_text) << stage << " " << it->first;
      }
    }
  };
  check("interpolate", naris::app::InterpolateSettings().table);
  check("segment", naris::app::SegmentSettings().table);
  check("mesh", naris::app::MeshSettings().table);
  check("solve", naris::app::SolveSettings().table);
  check("trace", naris::app::TraceSettings().table);
  check("planes", naris::app::PlanesSettings().table);
}

TEST_F(Cli, UnknownOptionIsAnError) {
  const CliRun r = naris("mesh --frobnicate");
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(r.err.rfind("naris: error: ", 0), 0u) << r.err;
}

}  // namespace

namespace {

class CliEog : public Cli {
 protected:
  // A two-column recording at 1 kHz of the rat single-cell model's response to 16 mM, 500 ms.
  fs::path recording(const std::string& name, unsigned seed) {
    const CliRun r = naris(
        "eog simulate --model rat-single-cell --pulse 16mM,500ms --onset 0.5 "
        "--length 6 -o " +
        (dir_ / "in" / "sim").string());
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream in(dir_ / "in" / "sim.csv");
    std::string header, line;
    std::getline(in, header);
    std::vector<double> y;
    while (std::getline(in, line)) y.push_back(std::stod(line.substr(line.rfind(',') + 1)));
    const fs::path p = dir_ / "in" / name;
    std::ofstream out(p);
    out << "Time (s)\tTrace (pA)\n";
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 2.0);
    for (int k = 0; k < 6000; ++k) {
      const double t = k / 1000.0, pos = t * 200.0;
      const auto i = std::min<std::size_t>(static_cast<std::size_t>(pos), y.size() - 2);
      const double w = pos - static_cast<double>(i);
      out << t << "\t" << (1 - w) * y[i] + w * y[i + 1] + noise(rng) << "\n";
    }
    return p;
  }
};

TEST_F(CliEog, SimulateWritesCsvAndPng) {
  const CliRun r = naris("eog simulate --model rat-single-cell --pulse 16mM,500ms -o " +
                         (dir_ / "out" / "resp").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "resp.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "resp.png"));
  EXPECT_NE(r.err.find("latency 0.260 s"), std::string::npos) << r.err;  // n_d = 52 at 200 Hz
}

TEST_F(CliEog, UnstablePresetIsRefusedUnlessStabilizedOrForced) {
  expect_clean_failure(naris("eog simulate --model dog-eog -o " + (dir_ / "out" / "r").string()),
                       "|z| = 1.01");
  EXPECT_EQ(
      naris("eog simulate --model dog-eog --stabilize -o " + (dir_ / "s" / "r").string()).status,
      0);
  EXPECT_EQ(
      naris("eog simulate --model dog-eog --force --length 2 -o " + (dir_ / "f" / "r").string())
          .status,
      0);
}

TEST_F(CliEog, FitRecoversAModelThatReproducesTheValidationRecord) {
  const fs::path fit = recording("fit.txt", 1), val = recording("val.txt", 2);
  const CliRun r = naris("eog fit --fit " + fit.string() + " --validation " + val.string() +
                         " --pulse 16mM,500ms --onset 0.5 --max-na 6 --max-nb 2 --min-nd 48 "
                         "--max-nd 56 -o " +
                         (dir_ / "out" / "model.yaml").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "model.png"));
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex(R"(([0-9.]+) % on the validation record)")))
      << r.err;
  const double percent = std::stod(m[1].str());
  EXPECT_GT(percent, 95.0) << r.err;
  // The fitted model simulates and predicts.
  const CliRun s = naris("eog predict --model " + (dir_ / "out" / "model.yaml").string() +
                         " --stimulus " + fit.string() + " -o " + (dir_ / "out" / "pred").string());
  EXPECT_EQ(s.status, 0) << s.err;
}

TEST_F(CliEog, BadRecordingsAreClearErrors) {
  std::ofstream(dir_ / "in" / "empty.txt") << "";
  std::ofstream(dir_ / "in" / "words.txt") << "time value\n0 1\n0.001 one\n";
  std::ofstream(dir_ / "in" / "back.txt") << "0 1\n0.002 1\n0.001 1\n0.003 1\n";
  std::ofstream(dir_ / "in" / "short.txt") << "0 1\n0.005 2\n0.010 3\n0.015 4\n";
  const std::string common =
      " --pulse 16mM,200ms --onset 0 -o " + (dir_ / "out" / "m.yaml").string();
  auto fit = [&](const std::string& f) {
    const std::string p = (dir_ / "in" / f).string();
    return naris("eog fit --fit " + p + " --validation " + p + common);
  };
  expect_clean_failure(fit("empty.txt"), "no data");
  expect_clean_failure(fit("words.txt"), "not two numbers");
  expect_clean_failure(fit("back.txt"), "decreases");
  expect_clean_failure(fit("short.txt"), "too short");
  expect_clean_failure(naris("eog simulate --model rat-single-cell --pulse 16,200 -o " +
                             (dir_ / "out" / "x").string()),
                       "not understood");
}

}  // namespace

namespace {

class CliSegment : public Cli {
 protected:
  // A 24³ CT-like float volume: tissue 40 HU, an air box (−1000 HU), noise of 20 HU.
  fs::path ct() {
    std::vector<float> v(24 * 24 * 24);
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.0f, 20.0f);
    for (int k = 0; k < 24; ++k)
      for (int j = 0; j < 24; ++j)
        for (int i = 0; i < 24; ++i) {
          const bool air = i > 4 && i < 18 && j > 6 && j < 16 && k > 3 && k < 20;
          v[static_cast<std::size_t>(i + 24 * (j + 24 * k))] =
              (air ? -1000.0f : 40.0f) + noise(rng);
        }
    return nrrd("ct.nrrd", "float", "24 24 24", payload(v));
  }
};

TEST_F(CliSegment, SegmentsThenMeshes) {
  const fs::path in = ct();
  const fs::path mask = dir_ / "out" / "airway.nrrd";
  const CliRun r = naris("segment " + in.string() + " --seed 10,10,10 -o " + mask.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // The air box spans i 5..17, j 7..15, k 4..19: 13·9·16 voxels.
  EXPECT_NE(r.err.find("airway " + std::to_string(13 * 9 * 16) + " voxels"), std::string::npos)
      << r.err;
  const CliRun m = naris("mesh " + mask.string() + " -o " + (dir_ / "out" / "mesh.h5").string());
  EXPECT_EQ(m.status, 0) << m.err;
  // Rotated and decimated first: with the threshold half-way between air and tissue, partial
  // volume cancels and the airway keeps its volume within the resampling error.
  const CliRun rd =
      naris("segment " + in.string() +
            " --threshold -480 --rotate i:30 --decimate 2 --seed \"11,11,11.5 mm\" -o " +
            (dir_ / "out" / "rotated.nrrd").string());
  ASSERT_EQ(rd.status, 0) << rd.err;
  std::smatch ml;
  ASSERT_TRUE(std::regex_search(rd.err, ml, std::regex(R"(voxels, ([0-9.]+) mL)"))) << rd.err;
  EXPECT_NEAR(std::stod(ml[1].str()), 13 * 9 * 16 * 1e-3, 0.15 * 13 * 9 * 16 * 1e-3) << rd.err;
}

TEST_F(CliSegment, BadSeedsAndThresholdsAreClearErrors) {
  const fs::path in = ct();
  const std::string out = " -o " + (dir_ / "out" / "a.nrrd").string();
  expect_clean_failure(naris("segment " + in.string() + " --seed 30,3,3" + out),
                       "outside the volume");
  expect_clean_failure(naris("segment " + in.string() + " --seed 1,1,1" + out), "not inside");
  expect_clean_failure(naris("segment " + in.string() + " --threshold -5000" + out),
                       "outside the data range");
  expect_clean_failure(naris("segment " + in.string() + " --threshold five" + out),
                       "neither a number");
}

TEST_F(CliSegment, InterpolatesGrayValuesAndMasks) {
  const fs::path in = ct();
  const fs::path fine = dir_ / "out" / "fine.nrrd";
  CliRun r = naris("interpolate " + in.string() + " --axis k --insert 2 -o " + fine.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("24×24×24 → 24×24×70"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("gray values"), std::string::npos) << r.err;
  // Shape-based interpolation of gray values segments them first and writes a labelmap, which
  // `segment` then grows from the seed as it is.
  const fs::path shape = dir_ / "out" / "shape.nrrd";
  r = naris("interpolate " + in.string() + " --method shape --axis k --insert 1 -o " +
            shape.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("segmented below"), std::string::npos) << r.err;
  r = naris("segment " + shape.string() + " --seed 10,10,20 -o " +
            (dir_ / "out" / "a.nrrd").string());
  ASSERT_EQ(r.status, 0) << r.err;
  // The air box spans k 4..19 of the acquired slices: 2·15 + 1 interpolated slices of 13·9.
  EXPECT_NE(r.err.find("airway " + std::to_string(13 * 9 * 31) + " voxels"), std::string::npos)
      << r.err;
}

TEST_F(Cli, InterpolateBadInput) {
  const fs::path one = nrrd("one.nrrd", "float", "12 12 1", payload(std::vector<float>(144)));
  const std::string o = " -o " + (dir_ / "out" / "x.nrrd").string();
  expect_clean_failure(naris("interpolate " + one.string() + o), "single slice");
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  expect_clean_failure(naris("interpolate " + in.string() + " --method cubic" + o), "method");
  expect_clean_failure(naris("interpolate " + in.string() + " --insert 2 --spacing 0.5" + o),
                       "give either insert or spacing, not both");
}

TEST_F(Cli, PhantomBadInput) {
  const std::string o = " -o " + (dir_ / "out" / "ct.nrrd").string();
  expect_clean_failure(naris("phantom --subject 0" + o), "subject");
  expect_clean_failure(naris("phantom --slice -3" + o), "slice");
}

class CliRunCase : public Cli {
 protected:
  fs::path write_case(const std::string& text) {
    const fs::path p = dir_ / "in" / "case.yaml";
    std::ofstream(p) << text;
    return p;
  }
  // A coarse phantom case (1 mm pixels) that runs in a few seconds.
  std::string coarse_case() const {
    return "output: " + (dir_ / "out").string() +
           "\nphantom: {subject: 2, pixel: 1.0, slice: 3.0}\n"
           "interpolate: {method: hsr, spacing: 1.0, block: 4, levels: 3}\n"
           "segment: {seed: [\"-9,0,8 mm\"]}\n"
           "mesh: {inlet: \"p=0,0,0;n=0,1,0\", outlet: \"p=0,96,0;n=0,1,0\"}\n";
  }
};

TEST_F(CliRunCase, RunsEveryStageThenSkipsThoseUpToDate) {
  const fs::path c = write_case(coarse_case());
  CliRun r = naris("run " + c.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"ct.nrrd", "exact.nrrd", "interpolated.nrrd", "airway.nrrd", "mesh/mesh.h5",
                        "mesh/mesh.vtu", "mesh/mesh.json"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / f)) << f;
  EXPECT_NE(r.err.find("patch     inlet"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("patch     outlet"), std::string::npos) << r.err;
  const std::regex dice_line("Dice (0\\.[0-9]+)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, dice_line)) << r.err;
  EXPECT_GT(std::stod(m[1]), 0.8);  // at 1 mm voxels the thin meatuses lose their edges
  r = naris("run " + c.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* stage : {"phantom", "interpolate", "segment", "mesh"})
    EXPECT_NE(r.err.find(std::string(stage) + ": up to date, skipped"), std::string::npos)
        << stage << "\n"
        << r.err;
  // Changing the segmentation reruns it and what follows, not what comes before.
  std::string text = coarse_case();
  text.replace(text.find("segment: {"), 10, "segment: {threshold: -400, ");
  write_case(text);
  r = naris("run " + c.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("interpolate: up to date, skipped"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("] segment\n"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("] mesh\n"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("threshold -400.0 HU (given)"), std::string::npos) << r.err;
  // A naris newer than the outputs (as after a rebuild) runs every stage again, once.
  const fs::path rebuilt = dir_ / "naris";
  fs::copy_file(NARIS_BINARY, rebuilt);
  for (int run = 0; run < 2; ++run) {
    const std::string err = dir_ / "stderr.txt";
    ASSERT_EQ(std::system((rebuilt.string() + " run " + c.string() + " 2> " + err).c_str()), 0);
    std::ifstream in(err);
    const std::string log((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(log.find("up to date, skipped") == std::string::npos, run == 0) << log;
  }
}

TEST_F(CliRunCase, BadCaseFilesAreClearErrors) {
  const std::string out = "output: " + (dir_ / "out").string() + "\n";
  const std::string mesh = "mesh: {}\n";
  expect_clean_failure(naris("run " + (dir_ / "in" / "absent.yaml").string()), "no such case");
  expect_clean_failure(naris("run " + write_case(out + "phantom: [1, 2\n").string()),
                       "not valid YAML");
  expect_clean_failure(
      naris("run " + write_case(out + "phantom: {}\nsolver: {}\n" + mesh).string()),
      "unknown setting 'solver'");
  expect_clean_failure(naris("run " + write_case(out + "phantom: {subjekt: 2}\n" + mesh).string()),
                       "unknown setting 'subjekt'");
  expect_clean_failure(
      naris("run " + write_case(out + "phantom: {subject: two}\n" + mesh).string()),
      "not a valid value");
  expect_clean_failure(
      naris("run " + write_case(out + "input: ct.nrrd\nphantom: {}\n" + mesh).string()),
      "either 'input'");
  expect_clean_failure(naris("run " + write_case(out + "phantom: {}\n").string()),
                       "no 'mesh' section");
  expect_clean_failure(naris("run " + write_case(out + "input: absent.nrrd\n" + mesh).string()),
                       "does not exist");
  expect_clean_failure(
      naris("run " +
            write_case(out + "phantom: {}\ninterpolate: {method: cubic}\n" + mesh).string()),
      "interpolate.method: 'cubic' is not one of hsr, linear, shape");
  expect_clean_failure(
      naris("run " + write_case(out + "phantom: {}\n" + mesh + "trace: {count: 5}\n").string()),
      "the trace stage needs a solve section");
  expect_clean_failure(
      naris("run " + write_case(out + "phantom: {}\n" + mesh + "planes: {}\n").string()),
      "the planes stage needs a solve section");
  expect_clean_failure(naris("run " + write_case(out + "phantom: {}\n" + mesh +
                                                 "solve: {}\ntrace: {release: rain}\n")
                                          .string()),
                       "trace.release: 'rain' is not one of");
}

TEST_F(Cli, SolvesTheFlowThroughACutBall) {
  const fs::path mesh = dir_ / "out" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  const fs::path solution = dir_ / "out" / "solution";
  // A PETSc option the solve reads is taken silently.
  CliRun r = naris("solve " + mesh.string() + " --re 20 --petsc \"-ns_ksp_type gmres\" -o " +
                   solution.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("never used"), std::string::npos) << r.err;
  for (const char* f : {"solution.h5", "solution.xdmf", "solution.vtu", "summary.json",
                        "residuals.csv", "checkpoint.h5"})
    EXPECT_TRUE(fs::exists(solution / f)) << f;
  // Mass balance and the restart, from summary.json (six significant digits).
  const double inflow = summary(solution, "flow_ml_s");
  EXPECT_GT(inflow, 0.0);
  EXPECT_NEAR(summary(solution, "outlet_flow_ml_s"), inflow, 1e-5 * inflow);
  // Restarting from a checkpoint at a lower Re reaches the same answer.
  const double direct = summary(solution, "pressure_drop_pa");
  EXPECT_GT(direct, 0.0);
  const fs::path low = dir_ / "out" / "low";
  ASSERT_EQ(naris("solve " + mesh.string() + " --re 8 -o " + low.string()).status, 0);
  const fs::path resumed = dir_ / "out" / "resumed";
  r = naris("solve " + mesh.string() + " --re 20 --restart " + (low / "checkpoint.h5").string() +
            " -o " + resumed.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("restarting from Re 8.0"), std::string::npos) << r.err;
  EXPECT_NEAR(summary(resumed, "pressure_drop_pa"), direct, 1e-5 * direct);
  EXPECT_NEAR(summary(resumed, "max_speed_m_s"), summary(solution, "max_speed_m_s"),
              1e-5 * summary(solution, "max_speed_m_s"));
  // A constant expression is the uniform profile: the same answer, and the summary says which.
  const fs::path typed = dir_ / "out" / "typed";
  // A misspelt PETSc option changes nothing, and the solve says so.
  r = naris("solve " + mesh.string() +
            " --re 20 --inlet-expression \"3 + 0*x*r\" --petsc \"-ns_ksp_typo gmres\" -o " +
            typed.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("PETSc option -ns_ksp_typo gmres was never used"), std::string::npos)
      << r.err;
  EXPECT_NEAR(summary(typed, "pressure_drop_pa"), direct, 1e-5 * direct);
  std::ifstream file(typed / "summary.json");
  const std::string text((std::istreambuf_iterator<char>(file)), {});
  EXPECT_NE(text.find("\"inlet_profile\": \"expression 3 + 0*x*r\""), std::string::npos) << text;
}

// Progress on long work: with --progress S a solve prints a nonlinear step's line once S
// seconds have passed since the last, and a Krylov line every S seconds of a linear solve; the
// cut ball solves in a fraction of a second, so a tiny S prints them all, and 0 none.
TEST_F(Cli, LongSolvesPrintProgress) {
  const fs::path mesh = dir_ / "ball" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  const std::regex step_line("\\n    (Picard|Newton) +[0-9]+: residual ");
  const std::regex krylov_line("\\n      gmres +[0-9]+: residual [0-9.e+-]+ of the solve's first");
  CliRun r = naris("solve " + mesh.string() + " --re 20 --progress 1e-9 -o " +
                   (dir_ / "ball" / "often").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::regex_search(r.err, step_line)) << r.err;
  EXPECT_TRUE(std::regex_search(r.err, krylov_line)) << r.err;
  for (const char* every : {"0", "60"}) {
    r = naris("solve " + mesh.string() + " --re 20 --progress " + every + " -o " +
              (dir_ / "ball" / "never").string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(std::regex_search(r.err, step_line)) << every << ":\n" << r.err;
    EXPECT_FALSE(std::regex_search(r.err, krylov_line)) << every << ":\n" << r.err;
  }
  expect_clean_failure(
      naris("solve " + mesh.string() + " --progress -1 -o " + (dir_ / "out").string()),
      "--progress");
}

// A checkpoint taken while following a branch by arclength resumes on the branch: from the
// Newton steps at Re 6 and 8 through the cut ball, marked as points of a branch, the run follows
// it by arclength until Re passes 20, converges at 20 itself — the answer of a run that goes
// there by Re alone — and lists the points in branch.csv, Re rising along this branch.
TEST_F(Cli, ResumedBranchIsFollowedByArclengthToTheTarget) {
  const fs::path mesh = dir_ / "out" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  const std::string solve = "solve " + mesh.string() + " --pseudo-cfl 0";
  const fs::path direct = dir_ / "out" / "direct", low = dir_ / "out" / "low",
                 branch = dir_ / "out" / "branch";
  ASSERT_EQ(naris(solve + " --re 20 -o " + direct.string()).status, 0);
  ASSERT_EQ(naris(solve + " --re 8 --re-start 6 -o " + low.string()).status, 0);
  naris::airflow::SolutionState point = naris::airflow::read_solution_h5(low / "checkpoint.h5");
  ASSERT_EQ(point.continuation.earlier_reynolds, 6.0);
  point.continuation.arclength_step = 0.25;
  naris::airflow::write_solution_h5(point, dir_ / "branch-point.h5");
  const CliRun r = naris(solve + " --re 20 --restart " + (dir_ / "branch-point.h5").string() +
                         " -o " + branch.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("by arclength"), std::string::npos) << r.err;
  EXPECT_NEAR(summary(branch, "pressure_drop_pa"), summary(direct, "pressure_drop_pa"),
              1e-5 * summary(direct, "pressure_drop_pa"));
  EXPECT_NEAR(summary(branch, "max_speed_m_s"), summary(direct, "max_speed_m_s"),
              1e-5 * summary(direct, "max_speed_m_s"));
  std::ifstream csv(branch / "branch.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "reynolds,arclength,pressure_drop_pa,max_speed_m_s,newton_steps");
  std::vector<double> re;
  while (std::getline(csv, line)) re.push_back(std::stod(line));
  ASSERT_GE(re.size(), 4u);  // the two given points, one on the branch at least, the target
  EXPECT_EQ(re.front(), 6.0);
  EXPECT_EQ(re.back(), 20.0);
  EXPECT_TRUE(std::is_sorted(re.begin(), re.end()));
}

// A solution on a mesh starts the solve on that mesh subdivided: prolonged onto it, at the
// target itself, it converges to the answer of a run from rest on the finer mesh. A checkpoint
// of a mesh the finer one does not subdivide is refused.
TEST_F(Cli, RestartOnTheSubdividedMeshProlongsTheCoarseSolution) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const fs::path coarse = dir_ / "coarse" / "mesh.h5", fine = dir_ / "fine" / "mesh.h5",
                 other = dir_ / "other" / "mesh.h5";
  const std::string cuts = " --inlet k=3 --outlet k=8";
  ASSERT_EQ(naris("mesh " + in.string() + cuts + " -o " + coarse.string()).status, 0);
  ASSERT_EQ(naris("mesh " + in.string() + cuts + " --subdivide 1 -o " + fine.string()).status, 0);
  ASSERT_EQ(naris("mesh " + in.string() + " --inlet k=3 --outlet k=7 -o " + other.string()).status,
            0);
  const fs::path low = dir_ / "low", other_low = dir_ / "other-low", direct = dir_ / "direct",
                 prolonged = dir_ / "prolonged";
  ASSERT_EQ(naris("solve " + coarse.string() + " --re 8 -o " + low.string()).status, 0);
  ASSERT_EQ(naris("solve " + fine.string() + " --re 8 -o " + direct.string()).status, 0);
  const CliRun r =
      naris("solve " + fine.string() + " --re 8 --restart " + (low / "checkpoint.h5").string() +
            " --restart-mesh " + coarse.string() + " -o " + prolonged.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("prolonged onto this mesh"), std::string::npos) << r.err;
  EXPECT_NEAR(summary(prolonged, "pressure_drop_pa"), summary(direct, "pressure_drop_pa"),
              1e-5 * summary(direct, "pressure_drop_pa"));
  ASSERT_EQ(naris("solve " + other.string() + " --re 8 -o " + other_low.string()).status, 0);
  expect_clean_failure(naris("solve " + fine.string() + " --re 8 --restart " +
                             (other_low / "checkpoint.h5").string() + " --restart-mesh " +
                             other.string() + " " + out()),
                       "is not");
  expect_clean_failure(
      naris("solve " + fine.string() + " --re 8 --restart " + (low / "checkpoint.h5").string() +
            " --restart-mesh " + other.string() + " " + out()),
      "belongs to another mesh");
}

// A run stopped after two continuation steps and resumed from its checkpoint takes the steps
// the uninterrupted run took: the same Re, method and residuals (the checkpoint keeps the
// next increment, the method and the earlier step of the secant predictor) — with pseudo-time
// (the default, every step after the first from rest) and with Newton alone (the predictor).
TEST_F(Cli, RestartTakesTheUninterruptedPath) {
  const fs::path mesh = dir_ / "out" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  // residuals.csv rows without the step number: Re, converged, iteration, residual.
  auto rows = [](const fs::path& folder) {
    std::ifstream file(folder / "residuals.csv");
    std::vector<std::string> out;
    std::string line;
    std::getline(file, line);
    while (std::getline(file, line)) out.push_back(line.substr(line.find(',') + 1));
    return out;
  };
  for (const std::string options : {"", " --pseudo-cfl 0"}) {
    SCOPED_TRACE(options);
    // Whether a preconditioner is kept follows counted work, not measured time, so the
    // linear solves, and the residuals to their last digits, are the same on every run.
    const std::string solve = "solve " + mesh.string() + " --re 20 --re-start 4" + options;
    const fs::path whole = dir_ / "out" / "whole", stopped = dir_ / "out" / "stopped",
                   resumed = dir_ / "out" / "resumed";
    CliRun r = naris(solve + " -o " + whole.string());
    ASSERT_EQ(r.status, 0) << r.err;
    r = naris(solve + " --max-steps 2 -o " + stopped.string());
    ASSERT_NE(r.status, 0);
    EXPECT_NE(r.err.find("in 2 steps"), std::string::npos) << r.err;
    // Newton's second step has the first for its predictor.
    const naris::continuation::ContinuationState c =
        naris::airflow::read_solution_h5(stopped / "checkpoint.h5").continuation;
    EXPECT_GT(c.next_step, 0.0);
    EXPECT_EQ(c.pseudo_time, options.empty());
    EXPECT_EQ(c.earlier_reynolds > 0.0, !options.empty()) << c.earlier_reynolds;
    r = naris(solve + " --restart " + (stopped / "checkpoint.h5").string() + " -o " +
              resumed.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const auto all = rows(whole), first = rows(stopped), rest = rows(resumed);
    ASSERT_FALSE(first.empty());
    ASSERT_FALSE(rest.empty());
    ASSERT_EQ(first.size() + rest.size(), all.size());
    EXPECT_TRUE(std::equal(first.begin(), first.end(), all.begin()));
    // The Re of the steps after the restart, and their residual histories to the printed
    // digits.
    EXPECT_TRUE(std::equal(rest.begin(), rest.end(), all.begin() + static_cast<long>(first.size())))
        << rest.front() << " against " << all[first.size()];
    EXPECT_NEAR(summary(resumed, "pressure_drop_pa"), summary(whole, "pressure_drop_pa"),
                1e-6 * summary(whole, "pressure_drop_pa"));
    fs::remove_all(whole);
    fs::remove_all(stopped);
    fs::remove_all(resumed);
  }
}

// naris solve --stability N: at Re 20 the flow is nearly Stokes flow, whose perturbations all
// decay (Re λ > 0 for every eigenvalue); the modes reach summary.json and the log, and two
// ranks find the same eigenvalues as one.
TEST_F(Cli, StabilityOfASlowFlowFindsOnlyDecayingModesOnOneAndTwoRanks) {
  const fs::path mesh = dir_ / "in" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  const fs::path one = dir_ / "one", two = dir_ / "two";
  const std::string solve = "solve " + mesh.string() + " --re 20 --tolerance 1e-10 --stability 3";
  CliRun r = naris(solve + " -o " + one.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("eigenvalues nearest 0 at Re 20.00"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("none grows"), std::string::npos) << r.err;
  r = naris(solve + " -o " + two.string(),
            "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " +
                std::string(NARIS_MPIEXEC) + " -n 2 --oversubscribe ");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto modes = [](const fs::path& folder) {
    std::ifstream file(folder / "summary.json");
    const nlohmann::json j = nlohmann::json::parse(file);
    std::vector<std::array<double, 3>> out;  // Re λ, Im λ, growth rate
    for (const auto& m : j.at("stability"))
      out.push_back({m.at("eigenvalue_real").get<double>(), m.at("eigenvalue_imag").get<double>(),
                     m.at("growth_rate_per_s").get<double>()});
    std::sort(out.begin(), out.end());
    return out;
  };
  const auto a = modes(one), b = modes(two);
  // Three, or four where the third is half of a complex pair: a pair is never split.
  ASSERT_GE(a.size(), 3u);
  ASSERT_LE(a.size(), 4u);
  ASSERT_EQ(b.size(), a.size());
  for (const auto& m : a)
    EXPECT_EQ(std::count_if(a.begin(), a.end(),
                            [&](const auto& o) {
                              const double size = std::hypot(m[0], m[1]);
                              return std::abs(o[0] - m[0]) <= 1e-5 * size &&
                                     std::abs(o[1] + m[1]) <= 1e-5 * size;
                            }),
              1)
        << "the conjugate of " << m[0] << " " << m[1];
  const double u_in = summary(one, "inlet_speed_m_s"),
               d_in = summary(one, "inlet_hydraulic_diameter_mm") * 1e-3;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_GT(a[k][0], 0.0) << k;
    // The growth rate is −Re λ in the solver's time unit d_in / U_in (four numbers of six
    // significant digits each).
    EXPECT_NEAR(a[k][2], -a[k][0] * u_in / d_in, 3e-5 * std::abs(a[k][2])) << k;
    const double size = std::hypot(a[k][0], a[k][1]);
    EXPECT_NEAR(b[k][0], a[k][0], 1e-5 * size) << k;
    EXPECT_NEAR(b[k][1], a[k][1], 1e-5 * size) << k;
  }
}

// The same binary under mpiexec: two ranks share the solves, one writes all but the volume,
// which each rank writes a piece of; the answer is the serial one to the six digits of
// summary.json.
TEST_F(Cli, SolveOnTwoRanksMatchesOneRank) {
  const fs::path mesh = dir_ / "in" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  const fs::path one = dir_ / "one", two = dir_ / "two";
  ASSERT_EQ(naris("solve " + mesh.string() + " --re 40 -o " + one.string()).status, 0);
  const CliRun r = naris("solve " + mesh.string() + " --re 40 -o " + two.string(),
                         // Open MPI refuses root (CI runs as root) unless told.
                         "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " +
                             std::string(NARIS_MPIEXEC) + " -n 2 --oversubscribe ");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("2 MPI ranks"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("naris solve: mesh.h5"), r.err.rfind("naris solve: mesh.h5")) << r.err;
  // The first patch's forces and shear are summed over the ranks' faces.
  for (const char* key : {"pressure_drop_pa", "max_speed_m_s", "outlet_flow_ml_s", "area_mm2",
                          "mean_wall_shear_pa", "max_wall_shear_pa"})
    EXPECT_NEAR(summary(two, key), summary(one, key), 2e-6 * std::abs(summary(one, key))) << key;
  // The fields each rank solved on its piece, gathered into one file.
  const naris::airflow::SolutionState a = naris::airflow::read_solution_h5(one / "solution.h5"),
                                      b = naris::airflow::read_solution_h5(two / "solution.h5");
  ASSERT_EQ(a.field.pressure.size(), b.field.pressure.size());
  double speed = 0.0, du = 0.0;
  for (std::size_t k = 0; k < a.field.velocity.size(); ++k) {
    speed = std::max(speed, a.field.velocity[k].norm());
    du = std::max(du, (a.field.velocity[k] - b.field.velocity[k]).norm());
  }
  EXPECT_LT(du, 1e-6 * speed);
  // The wall shear of every face, gathered from the ranks' pieces.
  EXPECT_EQ(fs::file_size(two / "boundary.vtp"), fs::file_size(one / "boundary.vtp"));
  // The volume as ParaView's parallel format, a piece per rank, instead of one file.
  for (const char* f : {"solution.pvtu", "solution_0.vtu", "solution_1.vtu"})
    EXPECT_TRUE(fs::exists(two / f)) << f;
  EXPECT_FALSE(fs::exists(two / "solution.vtu"));
  EXPECT_FALSE(fs::exists(one / "solution.pvtu"));
  // Each rank's cells carry the fine-scale velocity of the whole mesh's (their nodes' recovered
  // gradients see every cell around them): cells matched by their centroids.
  const auto fine_by_centroid = [](auto& reader, const fs::path& file) {
    reader->SetFileName(file.c_str());
    reader->Update();
    vtkUnstructuredGrid* grid = reader->GetOutput();
    vtkDataArray* fine = grid->GetCellData()->GetArray("subgrid_velocity");
    std::map<std::array<long long, 3>, std::array<double, 3>> by_centroid;
    if (!fine) return by_centroid;
    for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c) {
      vtkIdType n = 0;
      const vtkIdType* ids = nullptr;
      grid->GetCellPoints(c, n, ids);
      std::array<double, 3> centre{};
      for (vtkIdType k = 0; k < n; ++k)
        for (int d = 0; d < 3; ++d) centre[d] += grid->GetPoint(ids[k])[d] / static_cast<double>(n);
      std::array<long long, 3> key{};
      for (int d = 0; d < 3; ++d) key[d] = std::llround(centre[d] * 1e6);
      const double* v = fine->GetTuple3(c);
      by_centroid[key] = {v[0], v[1], v[2]};
    }
    return by_centroid;
  };
  vtkNew<vtkXMLUnstructuredGridReader> serial;
  vtkNew<vtkXMLPUnstructuredGridReader> pieces;
  const auto fine_one = fine_by_centroid(serial, one / "solution.vtu");
  const auto fine_two = fine_by_centroid(pieces, two / "solution.pvtu");
  ASSERT_FALSE(fine_one.empty());
  ASSERT_EQ(fine_one.size(), fine_two.size());
  double largest = 0.0, fine_difference = 0.0;
  for (const auto& [key, v] : fine_one) {
    const auto other = fine_two.find(key);
    ASSERT_NE(other, fine_two.end());
    for (int d = 0; d < 3; ++d) {
      largest = std::max(largest, std::abs(v[d]));
      fine_difference = std::max(fine_difference, std::abs(v[d] - other->second[d]));
    }
  }
  EXPECT_GT(largest, 0.0);
  EXPECT_LT(fine_difference, 1e-5 * largest);  // the fields agree to 1e-6 (measured 1.3e-6)
  // Memory of every rank: the largest, and the sum, which two ranks make larger than either.
  EXPECT_EQ(summary(one, "mpi_ranks"), 1.0);
  EXPECT_EQ(summary(two, "mpi_ranks"), 2.0);
  EXPECT_EQ(summary(one, "peak_memory_all_ranks_mb"), summary(one, "peak_memory_mb"));
  EXPECT_GT(summary(two, "peak_memory_all_ranks_mb"), summary(two, "peak_memory_mb"));
  // A serial run into the same folder replaces the pieces with one file.
  ASSERT_EQ(naris("solve " + mesh.string() + " --re 40 -o " + two.string()).status, 0);
  EXPECT_TRUE(fs::exists(two / "solution.vtu"));
  for (const char* f : {"solution.pvtu", "solution_0.vtu", "solution_1.vtu"})
    EXPECT_FALSE(fs::exists(two / f)) << f;
}

TEST_F(Cli, SolveBadInput) {
  const fs::path in = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const fs::path closed = dir_ / "in" / "closed" / "mesh.h5";
  ASSERT_EQ(naris("mesh " + in.string() + " -o " + closed.string()).status, 0);
  const std::string o = " -o " + (dir_ / "out" / "solution").string();
  expect_clean_failure(naris("solve " + closed.string() + o), "no 'inlet' patch");
  const fs::path cut = dir_ / "in" / "cut" / "mesh.h5";
  ASSERT_EQ(naris("mesh " + in.string() + " --inlet k=3 --outlet k=8 -o " + cut.string()).status,
            0);
  expect_clean_failure(naris("solve " + cut.string() + " --re 0" + o), "must be positive");
  expect_clean_failure(naris("solve " + cut.string() + " --re -5" + o), "must be positive");
  expect_clean_failure(naris("solve " + cut.string() + " --re nan" + o),
                       "--re: 'nan' is not a number");
  expect_clean_failure(naris("solve " + cut.string() + " --inlet-expression \"1-(r\"" + o),
                       "inlet expression '1-(r'");
  expect_clean_failure(naris("solve " + cut.string() + " --inlet-expression \"r-1\"" + o),
                       "not negative");
  expect_clean_failure(
      naris("solve " + cut.string() + " --inlet-expression 1 --inlet-profile developed" + o),
      "give either inlet_profile or inlet_expression, not both");
  expect_clean_failure(naris("solve " + (dir_ / "in" / "absent.h5").string() + o), "absent.h5");
  const fs::path junk = dir_ / "in" / "junk.h5";
  std::ofstream(junk) << "not hdf5";
  expect_clean_failure(naris("solve " + junk.string() + o), "junk.h5");
  // Restart files: unreadable, or of another mesh.
  expect_clean_failure(naris("solve " + cut.string() + " --restart " + junk.string() + o),
                       "not an HDF5 file");
  const fs::path other = dir_ / "in" / "other";
  ASSERT_EQ(
      naris("mesh " + in.string() + " --inlet k=2 --outlet k=8 -o " + (other / "mesh.h5").string())
          .status,
      0);
  ASSERT_EQ(naris("solve " + (other / "mesh.h5").string() + " --re 5 -o " + other.string()).status,
            0);
  expect_clean_failure(
      naris("solve " + cut.string() + " --restart " + (other / "checkpoint.h5").string() + o),
      "another mesh");
  // A step that cannot converge (one nonlinear iteration allowed, to the final tolerance
  // 1e-8 at every step, which one iteration from the last Re does not reach): the increment is
  // halved until it falls below 1e-3 of the target, then one error line naming the checkpoint,
  // which still holds the last converged Re; the residual history of the failed steps is written.
  const fs::path good = dir_ / "in" / "good";
  const CliRun from_rest = naris("solve " + cut.string() + " --re 8 -o " + good.string());
  ASSERT_EQ(from_rest.status, 0) << from_rest.err;
  // From rest, pseudo-time goes first.
  EXPECT_NE(from_rest.err.find("8.0: converged after"), std::string::npos) << from_rest.err;
  EXPECT_EQ(from_rest.err.find("FAILED"), std::string::npos) << from_rest.err;
  EXPECT_NE(from_rest.err.find("with pseudo-time"), std::string::npos) << from_rest.err;
  auto bytes = [](const fs::path& f) {
    std::ifstream file(f, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(file)), {});
  };
  const std::string checkpoint = bytes(good / "checkpoint.h5");
  // A checkpoint whose continuation contradicts itself: its earlier step above its own Re.
  naris::airflow::SolutionState odd = naris::airflow::read_solution_h5(good / "checkpoint.h5");
  odd.continuation.earlier_reynolds = odd.reynolds + 1.0;
  odd.continuation.earlier = odd.field;
  naris::airflow::write_solution_h5(odd, dir_ / "in" / "odd.h5");
  expect_clean_failure(
      naris("solve " + cut.string() + " --restart " + (dir_ / "in" / "odd.h5").string() + o),
      "inconsistent continuation state");
  // Following a branch the earlier point may lie above in Re, but it must be another point.
  odd.continuation.arclength_step = 0.1;
  odd.continuation.earlier_reynolds = odd.reynolds;
  naris::airflow::write_solution_h5(odd, dir_ / "in" / "odd.h5");
  expect_clean_failure(
      naris("solve " + cut.string() + " --restart " + (dir_ / "in" / "odd.h5").string() + o),
      "inconsistent arclength state");
  const CliRun r = naris("solve " + cut.string() +
                         " --re 400 --max-iterations 1 --step-tolerance 1e-8 --restart " +
                         (good / "checkpoint.h5").string() + " -o " + good.string());
  EXPECT_NE(r.status, 0);
  const auto last = r.err.rfind("naris: error: ");
  ASSERT_NE(last, std::string::npos) << r.err;
  const std::string error = r.err.substr(last);
  EXPECT_EQ(std::count(error.begin(), error.end(), '\n'), 1) << error;
  EXPECT_NE(error.find("stalled at Re 8.0"), std::string::npos) << error;
  EXPECT_NE(error.find("holds the last converged step"), std::string::npos) << error;
  // The restart takes the increment the checkpoint stored, so the first Re tried is 8 + d (the
  // uninterrupted run's next step); it fails, then the halved increments 8 + d/2, 8 + d/4, … — each
  // with pseudo-time first (the from-rest step needed it) and again with Newton — until the
  // next would be below 1e-3 × 400. At the stall, with no Newton step on the branch yet, one
  // at 0.99 × 8 would give the secant to follow it by arclength; it fails here too.
  std::smatch next;
  ASSERT_TRUE(std::regex_search(r.err, next, std::regex("next Re ([0-9.]+)"))) << r.err;
  std::vector<double> tried;
  for (double d = std::stod(next[1]) - 8.0; d >= 0.4; d *= 0.5) tried.push_back(8.0 + d);
  ASSERT_GE(tried.size(), 3u) << r.err;
  std::vector<std::string> failures;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);)
    if (line.find("FAILED") != std::string::npos) failures.push_back(line);
  ASSERT_EQ(failures.size(), 2 * tried.size() + 1) << r.err;
  EXPECT_NE(failures.back().find("Re     7.92: FAILED"), std::string::npos) << failures.back();
  EXPECT_NE(failures.back().find("a second point of the branch"), std::string::npos);
  failures.pop_back();
  for (std::size_t k = 0; k < failures.size(); ++k) {
    std::smatch re;
    ASSERT_TRUE(std::regex_search(failures[k], re, std::regex("Re +([0-9.]+): FAILED")))
        << failures[k];
    EXPECT_NEAR(std::stod(re[1]), tried[k / 2], 0.051) << failures[k];
    EXPECT_EQ(failures[k].find("with pseudo-time") != std::string::npos, k % 2 == 0) << failures[k];
  }
  EXPECT_EQ(bytes(good / "checkpoint.h5"), checkpoint);
  std::ostringstream first;
  first << "\n0," << tried[0] << ",0,0,";
  EXPECT_NE(bytes(good / "residuals.csv").find(first.str()), std::string::npos);
}

}  // namespace

// naris trace on the cut ball's flow: every particle ends with one fate, none is lost, and two
// ranks write the same particles and crossings as one.
TEST_F(Cli, TracesTheCutBallOnOneAndTwoRanks) {
  const fs::path mesh = dir_ / "in" / "mesh.h5", flow = dir_ / "in" / "flow";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  ASSERT_EQ(naris("solve " + mesh.string() + " --re 20 -o " + flow.string()).status, 0);
  const std::string args = "trace " + (flow / "solution.h5").string() +
                           " --release random --count 10000 --planes 1.5,3 --diameter 3,30 ";
  const fs::path one = dir_ / "one", two = dir_ / "two";
  CliRun r = naris(args + "-o " + one.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = naris(args + "-o " + two.string(),
            "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " +
                std::string(NARIS_MPIEXEC) + " -n 2 --oversubscribe ");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(summary(one, "particles"), 20000.0);
  EXPECT_EQ(summary(one, "lost"), 0.0);
  double ended = 0.0;
  for (const char* fate : {"outlet", "inlet", "wall", "max-time", "stagnated"})
    ended += summary(one, fate);
  EXPECT_EQ(ended, 20000.0);
  EXPECT_GT(summary(one, "wall"), 0.0);  // 30 µm particles settle onto the ball's floor
  EXPECT_EQ(summary(two, "mpi_ranks"), 2.0);
  for (const char* f : {"particles.csv", "crossings.csv", "fates.csv"}) {
    std::ifstream a(one / f), b(two / f);
    const std::string ta((std::istreambuf_iterator<char>(a)), {}),
        tb((std::istreambuf_iterator<char>(b)), {});
    EXPECT_GT(ta.size(), 100u) << f;
    EXPECT_EQ(ta, tb) << f;
  }
  for (const char* f : {"paths.vtp", "deposits.vtp", "summary.json", "paths.png", "crossings.png"})
    EXPECT_TRUE(fs::exists(one / f)) << f;
}

TEST_F(Cli, TraceBadInput) {
  const fs::path mesh = dir_ / "in" / "mesh.h5", flow = dir_ / "in" / "flow";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  ASSERT_EQ(naris("solve " + mesh.string() + " --re 5 -o " + flow.string()).status, 0);
  const std::string trace =
      "trace " + (flow / "solution.h5").string() + " -o " + (dir_ / "out").string() + " ";
  // A solution of another mesh.
  const fs::path in = nrrd("ball2.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const fs::path other = dir_ / "in" / "other.h5";
  ASSERT_EQ(naris("mesh " + in.string() + " --inlet k=2 --outlet k=8 -o " + other.string()).status,
            0);
  expect_clean_failure(naris(trace + "--mesh " + other.string()), "was not solved on");
  // A release point outside the airway, named.
  const fs::path points = dir_ / "in" / "points.csv";
  std::ofstream(points) << "x,y,z\n5.5,5.7,5.0\n50,50,50\n";
  expect_clean_failure(naris(trace + "--release points --points " + points.string()),
                       "release point 2 (50, 50, 50 mm) lies outside the airway");
  expect_clean_failure(naris(trace + "--offset 20"), "too small for release groups 20 mm");
  expect_clean_failure(naris(trace + "--diameter 5,-1"), "diameter -1 µm: must not be negative");
  expect_clean_failure(naris(trace + "--diameter 5 --density -3"),
                       "density -3 kg/m³: must be positive");
  expect_clean_failure(naris(trace + "--planes 500"), "plane at 500 mm: the airway runs");
  expect_clean_failure(naris(trace + "--plane \"p=0,0,-40;n=0,0,1\""), "misses the airway");
  expect_clean_failure(naris(trace + "--release grid --count 0"), "must be positive");
  expect_clean_failure(naris(trace + "--points " + points.string()),
                       "points needs release: points");
}

// Planes through the solved cut ball, with the crossings of a trace drawn on them: every file,
// the flux through each plane equal to the inlet's, and the table the summary's.
TEST_F(Cli, CutsPlanesThroughTheSolvedBall) {
  const fs::path mesh = dir_ / "in" / "mesh.h5", flow = dir_ / "in" / "flow";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  ASSERT_EQ(naris("solve " + mesh.string() + " --re 20 -o " + flow.string()).status, 0);
  const fs::path solution = flow / "solution.h5", trace = dir_ / "trace", out = dir_ / "planes";
  ASSERT_EQ(naris("trace " + solution.string() +
                  " --release random --count 200 --planes 1.5,3 -o " + trace.string())
                .status,
            0);
  const CliRun r = naris("planes " + solution.string() +
                         " --at 1.5,3 --plane \"p=5.5,5.5,5.2;n=0,0.3,1\" --crossings " +
                         (trace / "crossings.csv").string() + " -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"planes.csv", "planes.vtp", "summary.json", "plane-1.png", "plane-1.svg",
                        "plane-2.png", "plane-3.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  std::ifstream csv(out / "planes.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("plane,label,distance_mm,piece,area_mm2,perimeter_mm,raw_perimeter_mm,", 0),
            0u);
  int planes = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    if (f[3] != "all") continue;
    ++planes;
    // Flux / the inlet's: the ball is 8 voxels across, where the FE flow conserves mass to a
    // few per cent (the accuracy is tested on the Poiseuille pipe and on the phantom).
    EXPECT_NEAR(std::stod(f[9]), 1.0, 0.03) << line;
    EXPECT_GT(std::stod(f[4]), 10.0) << line;
  }
  EXPECT_EQ(planes, 3);
  EXPECT_GT(summary(out, "d_in_solution_mm"), 0.0);
  EXPECT_GT(summary(out, "crossings_drawn"), 0.0);  // plane 1's share of the trace's crossings
}

TEST_F(Cli, PlanesBadInput) {
  const fs::path mesh = dir_ / "in" / "mesh.h5", flow = dir_ / "in" / "flow";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  ASSERT_EQ(naris("solve " + mesh.string() + " --re 5 -o " + flow.string()).status, 0);
  const std::string planes =
      "planes " + (flow / "solution.h5").string() + " -o " + (dir_ / "out").string() + " ";
  const fs::path in = nrrd("ball2.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const fs::path other = dir_ / "in" / "other.h5";
  ASSERT_EQ(naris("mesh " + in.string() + " --inlet k=2 --outlet k=8 -o " + other.string()).status,
            0);
  expect_clean_failure(naris(planes + "--mesh " + other.string()), "was not solved on");
  expect_clean_failure(naris(planes + "--at 2,40"), "plane at 40 mm: the airway runs");
  expect_clean_failure(naris(planes + "--at \"\" --plane \"p=0,0,-40;n=0,0,1\""),
                       "misses the airway");
  expect_clean_failure(naris(planes + "--at \"\""), "no planes");
  expect_clean_failure(naris(planes + "--axis w"), "is not one of");
  expect_clean_failure(naris(planes + "--smoothing 0"), "must be positive");
  expect_clean_failure(naris(planes + "--levels 1"), "levels");
  expect_clean_failure(naris(planes + "--at 2 --crossings " + (dir_ / "none.csv").string()),
                       "cannot read the crossings");
  expect_clean_failure(
      naris("planes " + (dir_ / "absent.h5").string() + " -o " + (dir_ / "out").string()),
      "absent.h5");
}

// Two subjects (the cut ball at two Reynolds numbers) compared: the table's numbers are the
// summaries' own, and every file is written.
TEST_F(Cli, ComparesSubjectsFromTheirSummaries) {
  const fs::path mesh = dir_ / "in" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  for (const auto& [name, re] : {std::pair{"a", "20"}, std::pair{"b", "10"}}) {
    const fs::path s = dir_ / name;
    ASSERT_EQ(
        naris("solve " + mesh.string() + " --re " + re + " -o " + (s / "solution").string()).status,
        0);
    const std::string solution = (s / "solution" / "solution.h5").string();
    ASSERT_EQ(
        naris("trace " + solution + " --release random --count 50 -o " + (s / "trace").string())
            .status,
        0);
    ASSERT_EQ(naris("planes " + solution + " --at 1.5,3 -o " + (s / "planes").string()).status, 0);
  }
  const fs::path out = dir_ / "cmp";
  const CliRun r = naris("compare " + (dir_ / "a").string() + " " + (dir_ / "b").string() +
                         " --plane 2 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f :
       {"compare.csv", "compare.md", "plane-2.png", "plane-2.svg", "area-distance.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  std::ifstream csv(out / "compare.csv");
  std::string line;
  std::getline(csv, line);
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) header.push_back(item);
  }
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<std::size_t>(it - header.begin());
  };
  for (const char* name : {"a", "b"}) {
    ASSERT_TRUE(std::getline(csv, line));
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    ASSERT_EQ(f.size(), header.size()) << line;
    EXPECT_EQ(f[0], name);
    const fs::path s = dir_ / name;
    EXPECT_DOUBLE_EQ(std::stod(f[column("flow_ml_s")]), summary(s / "solution", "flow_ml_s"));
    EXPECT_DOUBLE_EQ(std::stod(f[column("pressure_drop_pa")]),
                     summary(s / "solution", "pressure_drop_pa"));
    EXPECT_DOUBLE_EQ(std::stod(f[column("d_in_mm")]),
                     summary(s / "solution", "inlet_hydraulic_diameter_mm"));
    EXPECT_DOUBLE_EQ(std::stod(f[column("max_speed_m_s")]),
                     summary(s / "solution", "max_speed_m_s"));
    std::ifstream planes(s / "planes" / "summary.json");
    const auto p = nlohmann::json::parse(planes);
    EXPECT_DOUBLE_EQ(std::stod(f[column("area_mm2_1.5 mm")]),
                     p["planes"][0]["all"]["area_mm2"].get<double>());
    EXPECT_DOUBLE_EQ(std::stod(f[column("max_speed_m_s_3 mm")]),
                     p["planes"][1]["all"]["max_speed_m_s"].get<double>());
    EXPECT_GT(std::stod(f[column("flux-weighted_outlet")]), 0.0);
  }
}

TEST_F(Cli, CompareBadInput) {
  const fs::path mesh = dir_ / "in" / "mesh.h5";
  ASSERT_NO_FATAL_FAILURE(mesh_cut_ball(mesh));
  for (const auto& [name, at] : {std::pair{"a", "1.5,3"}, std::pair{"b", "2"}}) {
    const fs::path s = dir_ / name;
    ASSERT_EQ(naris("solve " + mesh.string() + " --re 5 -o " + (s / "solution").string()).status,
              0);
    ASSERT_EQ(naris("planes " + (s / "solution" / "solution.h5").string() + " --no-figures --at " +
                    at + " -o " + (s / "planes").string())
                  .status,
              0);
  }
  ASSERT_EQ(
      naris("solve " + mesh.string() + " --re 5 -o " + (dir_ / "c" / "solution").string()).status,
      0);
  const std::string compare = "compare -o " + (dir_ / "out").string() + " ";
  const std::string a = (dir_ / "a").string(), b = (dir_ / "b").string(), c = (dir_ / "c").string();
  expect_clean_failure(naris(compare + a + " " + b), "have different planes");
  expect_clean_failure(naris(compare + a + " " + c), "no planes stage");
  expect_clean_failure(naris(compare + a), "two subjects or more");
  expect_clean_failure(naris(compare + "--profile-step 0 " + a + " " + b), "profile-step 0 mm");
  expect_clean_failure(naris(compare + a + " " + (dir_ / "in").string()), "neither a case folder");
  expect_clean_failure(naris(compare + a + " " + a), "two subjects are named 'a'");
  fs::copy(dir_ / "a", dir_ / "d", fs::copy_options::recursive);
  // A subject whose mesh says metres.
  const fs::path metres = dir_ / "m" / "mesh.h5";
  fs::create_directories(metres.parent_path());
  fs::copy(mesh, metres);
  ASSERT_EQ(
      naris("solve " + metres.string() + " --re 5 -o " + (dir_ / "m" / "solution").string()).status,
      0);
  ASSERT_EQ(naris("planes " + (dir_ / "m" / "solution" / "solution.h5").string() +
                  " --no-figures --at 1.5,3 -o " + (dir_ / "m" / "planes").string())
                .status,
            0);
  {
    const hid_t file = H5Fopen(metres.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    ASSERT_GE(H5Adelete(file, "units"), 0);
    naris::write_string_attribute(file, "units", "m", metres);
    H5Fclose(file);
  }
  expect_clean_failure(naris(compare + a + " " + (dir_ / "m").string()),
                       "a is in mm and m in m: compare subjects meshed in the same units");
  expect_clean_failure(naris(compare + "--plane 9 " + a + " " + (dir_ / "d").string()),
                       "plane 9: the subjects have planes 1 … 2");
}

// One NasalSeg adult (Zhang et al. 2024, CC BY 4.0) from the CT to the mesh: the right cavity
// found without seeds, meshed between its naris and its choana with the planes the
// segmentation wrote; nothing but wall, inlet and outlet bounds it.
TEST_F(Cli, NasalSegRightCavityFromTheCtToTheMesh) {
  const fs::path ct = fs::path(NARIS_SHARED_DATA) / "nasalseg" / "P005_img.nrrd";
  if (!fs::exists(ct)) GTEST_SKIP() << "shared data absent: " << ct;
  const fs::path airway = dir_ / "airway.nrrd";
  // Seeds are points the airway must hold (voxels of P005's scan): one in the right cavity is
  // held; one in bone, one in front of the face and one in the right maxillary sinus are not.
  CliRun r = naris("segment " + ct.string() + " --airway nasal --side right --seed 58,60,16 -o " +
                   airway.string());
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir_ / "airway.json"));
  ASSERT_TRUE(fs::exists(dir_ / "airway-regions.nrrd"));
  const std::string o = " -o " + (dir_ / "out" / "airway.nrrd").string();
  for (const auto& [seed, where] :
       {std::pair{"71,60,2", "in tissue or bone"}, std::pair{"10,2,30", "outside the body"},
        std::pair{"23,86,24", "in a paranasal sinus"}})
    expect_clean_failure(naris("segment " + ct.string() + " --airway nasal --seed " + seed + o),
                         where);
  r = naris("mesh " + airway.string() + " --inlet auto --outlet auto -o " +
            (dir_ / "mesh" / "mesh.h5").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("conforming, watertight"), std::string::npos) << r.err;
  std::ifstream file(dir_ / "mesh" / "mesh.json");
  const nlohmann::json mesh = nlohmann::json::parse(file);
  std::map<std::string, nlohmann::json> patches;
  for (const auto& p : mesh["patches"]) patches[p["name"].get<std::string>()] = p;
  EXPECT_EQ(patches.size(), 3u) << mesh["patches"].dump();
  ASSERT_TRUE(patches.count("inlet") && patches.count("outlet"));
  // An adult naris: tens of mm², a hydraulic diameter of a few mm.
  EXPECT_GT(patches["inlet"]["area_mm2"].get<double>(), 20.0);
  EXPECT_LT(patches["inlet"]["area_mm2"].get<double>(), 200.0);
  EXPECT_GT(patches["inlet"]["hydraulic_diameter_mm"].get<double>(), 1.5);
  EXPECT_LT(patches["inlet"]["hydraulic_diameter_mm"].get<double>(), 12.0);
  const double ml = mesh["volume_mm3"].get<double>() / 1000.0;
  EXPECT_GT(ml, 8.0);
  EXPECT_LT(ml, 20.0);
}

TEST_F(Cli, NasalAirwayRefusesLabelmapsAndStrayOptions) {
  const fs::path labels = nrrd("ball.nrrd", "uint8", "12 12 12", payload(ball_labels()));
  const std::string o = " -o " + (dir_ / "out" / "airway.nrrd").string();
  expect_clean_failure(naris("segment " + labels.string() + " --airway nasal" + o), "labelmap");
  std::vector<std::int16_t> ct(12 * 12 * 12, -1000);
  for (std::size_t q = 0; q < ct.size(); q += 3) ct[q] = 40;
  const fs::path scan = nrrd("ct.nrrd", "int16", "12 12 12", payload(ct));
  expect_clean_failure(naris("segment " + scan.string() + " --side left" + o), "airway nasal");
  expect_clean_failure(naris("segment " + scan.string() + " --airway nasal --side up" + o), "side");
  expect_clean_failure(naris("mesh " + labels.string() + " --inlet auto " + out()), "auto");
}

// A label map of two touching halves of a ball (labels 3 and 5) with 3D Slicer's segment names:
// --label 3,5 meshes their union as one object, a name selects its label, an absent label or
// name is an error that lists what is there, and interpolate keeps it a label map.
TEST_F(Cli, LabelsUnionsNamesAndLabelMapInterpolation) {
  std::vector<std::uint8_t> v = ball_labels();
  for (std::size_t q = 0; q < v.size(); ++q)
    if (v[q]) v[q] = (q % 12) < 6 ? 3 : 5;
  const fs::path in = dir_ / "in" / "halves.nrrd";
  {
    std::ofstream out(in, std::ios::binary);
    out << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 12 12 12\nencoding: raw\n"
           "Segment0_Name:=right half\nSegment0_LabelValue:=3\n"
           "Segment1_Name:=left half\nSegment1_LabelValue:=5\n\n"
        << payload(v);
  }
  auto volume = [](const fs::path& folder) {
    std::ifstream file(folder / "mesh.json");
    return nlohmann::json::parse(file)["volume_mm3"].get<double>();
  };
  const fs::path both = dir_ / "both", right = dir_ / "right", left = dir_ / "left";
  CliRun r = naris("mesh " + in.string() + " --label 3,5 -o " + (both / "mesh.h5").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("labels 3 + 5"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("dropped"), std::string::npos) << "the union is one object: " << r.err;
  r = naris("mesh " + in.string() + " --label 'right half' -o " + (right / "mesh.h5").string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = naris("mesh " + in.string() + " --label 5 -o " + (left / "mesh.h5").string());
  ASSERT_EQ(r.status, 0) << r.err;
  // The halves' walls meet inside the union: their volumes add up to about the whole.
  EXPECT_NEAR(volume(right) + volume(left), volume(both), 0.15 * volume(both));
  EXPECT_GT(volume(both), volume(right));
  expect_clean_failure(naris("mesh " + in.string() + " --label 3,4 " + out()),
                       "no voxel has label 4 (labels present: 0, 3 (right half), 5 (left half))");
  expect_clean_failure(naris("mesh " + in.string() + " --label nose " + out()), "no label 'nose'");
  // The union's wall on a smooth surface: the same object, a little less volume than the
  // chamfered staircase; a threshold field has no staircase to smooth.
  const fs::path smooth = dir_ / "smooth";
  r = naris("mesh " + in.string() + " --label 3,5 --smooth 1 -o " + (smooth / "mesh.h5").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NEAR(volume(smooth), volume(both), 0.1 * volume(both));
  expect_clean_failure(naris("mesh " + in.string() + " --threshold 2 --smooth 1 " + out()),
                       "--smooth is for labelmaps");
  const fs::path fine = dir_ / "fine.nrrd";
  r = naris("interpolate " + in.string() + " --insert 1 -o " + fine.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("label map of 2 labels"), std::string::npos) << r.err;
  r = naris("mesh " + fine.string() + " --label 5 -o " + (dir_ / "fine" / "mesh.h5").string());
  EXPECT_EQ(r.status, 0) << r.err;
}
