// The files a filter reads and writes (gi/filter_files.h), which a front end
// checks before it computes: the list agrees with what the run then names;
// writeOutputFiles goes through the front end's writer; a PNG that cannot be
// written is one exception and nothing on stderr. And the writer the
// command-line tool uses (io/atomic_file.h): whole or not at all.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "atomic_file.h"
#include "gi/error_map.h"
#include "gi/filter_files.h"
#include "gi/filter_run.h"
#include "gi/form_factors.h"
#include "gi/radiosity.h"
#include "gi/scenes.h"
#include "filter_input.h"

using namespace gi;
namespace fs = std::filesystem;

namespace {

FilterInput input(FilterKind kind, const scenes::SceneFile& sf) { return test::filterInput(kind, sf); }

std::set<std::string> written(const FilterFiles& f) {
  std::set<std::string> s;
  for (const NamedFile& w : f.writes) s.insert(w.path);
  return s;
}

// Every path writeOutputFiles hands its writer, in order.
std::vector<std::string> pathsWritten(const FilterResult& r) {
  std::vector<std::string> paths;
  writeOutputFiles(r, [&](const std::string& path, const std::function<void(const std::string&)>&) { paths.push_back(path); });
  return paths;
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("gi_filter_files_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

std::string readAll(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

}  // namespace

TEST(FilterFiles, HemicubeNamesItsThreePicturesAndTheirPfm) {
  FilterInput in = input(FilterKind::HemicubeOfFace, scenes::closedBox(1.0, 2, true));
  in.values.set("face_index", 0);
  in.values.set("hemicube_resolution", 16);
  in.values.set("nusselt_resolution", 16);
  in.values.set("image_path", std::string("out/hc.png"));
  const FilterFiles plan = filterFiles(FilterKind::HemicubeOfFace, in.values);
  const FilterResult r = runFilter(FilterKind::HemicubeOfFace, in);
  const std::vector<std::string> paths = pathsWritten(r);
  EXPECT_EQ(std::set<std::string>(paths.begin(), paths.end()), written(plan));
  EXPECT_EQ(paths.size(), 6u);
  EXPECT_TRUE(written(plan).count("out/hc_nusselt.pfm"));
  in.values.set("image_path", std::string());
  EXPECT_TRUE(filterFiles(FilterKind::HemicubeOfFace, in.values).writes.empty());
  // The pictures are PNG: a name promising another format is refused before
  // any work (it held PNG data under .jpg), a capital .PNG is accepted.
  for (const char* bad : {"out/hc.jpg", "out/hc", "out.d/hc"}) {
    in.values.set("image_path", std::string(bad));
    EXPECT_THROW(filterFiles(FilterKind::HemicubeOfFace, in.values), std::invalid_argument) << bad;
    EXPECT_THROW(filterFiles(FilterKind::RayTracedView, in.values), std::invalid_argument) << bad;
  }
  in.values.set("image_path", std::string("out/HC.PNG"));
  EXPECT_TRUE(written(filterFiles(FilterKind::HemicubeOfFace, in.values)).count("out/HC_dff.png"));
}

TEST(FilterFiles, RadiosityNamesItsCsvAndEveryMatrix) {
  FilterInput in = input(FilterKind::Radiosity, scenes::cornellBox(150.0));
  in.values.set("form_factor_method", int(kFormFactorMethods.index(FormFactorMethod::MonteCarlo)));
  in.values.set("rays_per_patch", 16);
  in.values.set("residual_csv", std::string("r.csv"));
  in.values.set("export_system", std::string("dir/sys"));
  const FilterFiles plan = filterFiles(FilterKind::Radiosity, in.values);
  const FilterResult r = runFilter(FilterKind::Radiosity, in);
  ASSERT_EQ(r.files.size(), 7u);  // the CSV and six matrices: the matrix was in memory
  const std::vector<std::string> paths = pathsWritten(r);
  EXPECT_EQ(std::set<std::string>(paths.begin(), paths.end()), written(plan));
  EXPECT_TRUE(plan.reads.empty());
  EXPECT_TRUE(plan.layers.empty());
}

TEST(FilterFiles, ReferenceFileOnlyWhenTheReferenceComesFromAFile) {
  ParamValues v = defaultValues(filterSpecs(FilterKind::ErrorMap), 1.0);
  v.set("reference_file", std::string("ref.ply"));
  EXPECT_TRUE(filterFiles(FilterKind::ErrorMap, v).reads.empty());
  v.set("reference_source", int(kReferenceSources.index(ReferenceSource::File)));
  const FilterFiles f = filterFiles(FilterKind::ErrorMap, v);
  ASSERT_EQ(f.reads.size(), 1u);
  EXPECT_EQ(f.reads[0].path, "ref.ply");
  EXPECT_EQ(f.reads[0].parameter, "reference_file");
}

TEST(FilterFiles, PhotonLayerOnlyWhenAsked) {
  ParamValues v = defaultValues(filterSpecs(FilterKind::PhotonMapping), 1.0);
  EXPECT_TRUE(filterFiles(FilterKind::PhotonMapping, v).layers.empty());
  v.set("photon_layer", true);
  EXPECT_EQ(filterFiles(FilterKind::PhotonMapping, v).layers, std::vector<std::string>{"Photons"});
  EXPECT_EQ(pfmPath("a.b/c"), "a.b/c.pfm");
  EXPECT_EQ(pfmPath("dir/img.png"), "dir/img.pfm");
}

// libpng's default handlers printed "libpng error: Write Error" before our
// exception, two lines where the command-line tool promises one.
TEST(FilterFiles, FailedPngIsOneExceptionAndNothingOnStderr) {
  ASSERT_TRUE(fs::exists("/dev/full")) << "Linux's /dev/full (always full) is needed";
  Image img(256, 256);  // noise: the compressed rows overflow stdio's buffer, so libpng's own write fails
  uint32_t h = 1;
  for (glm::vec3& p : img.px)
    for (int k = 0; k < 3; ++k) p[k] = float((h = h * 1664525u + 1013904223u) >> 8) / 16777216.f;
  testing::internal::CaptureStderr();
  bool threw = false;
  try {
    writePng("/dev/full", img, 1.f);
  } catch (const std::runtime_error& e) {
    threw = std::string(e.what()).find("/dev/full") != std::string::npos;
  }
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_TRUE(threw);
  EXPECT_EQ(err, "");
}

TEST(AtomicFile, FailedWriteKeepsTheFileAndLeavesNoTemporary) {
  const fs::path p = scratch("keep.txt");
  io::writeFileAtomically(p.string(), "good");
  ::chmod(p.c_str(), 0640);
  EXPECT_THROW(io::writeAtomically(p.string(),
                                   [](const std::string& temp) {
                                     std::ofstream(temp) << "par";
                                     throw std::runtime_error("cannot write " + temp + ": disk full");
                                   }),
               std::runtime_error);
  EXPECT_EQ(readAll(p), "good");
  try {  // the message names the file, not the temporary
    io::writeAtomically(p.string(), [](const std::string& temp) { throw std::runtime_error("cannot write " + temp); });
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write " + p.string());
  }
  io::writeFileAtomically(p.string(), "better");
  EXPECT_EQ(readAll(p), "better");
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);  // the replaced file's permissions
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(p.parent_path())) files += e.path().filename() != "keep.txt";
  EXPECT_EQ(files, 0u);
  fs::remove_all(p.parent_path());
}

// A process killed outright (SIGKILL, the out-of-memory killer) cannot
// remove its temporary: the next run that writes into the folder removes
// those of processes that no longer run, once they are 10 minutes old (a
// younger one may be another machine's writer in a shared folder). Those
// of running processes, younger ones and files not named as ours stay.
TEST(AtomicFile, LeftoverTemporariesOfKilledRunsAreRemoved) {
  const fs::path dir = scratch("leftovers");  // a folder of its own: each is read once per process
  fs::create_directories(dir);
  const fs::path p = dir / "out.ply";
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);  // a process id that runs nothing now
  const std::string dead = std::to_string(child);
  const auto make = [&](const std::string& name, bool old) {
    std::ofstream(dir / name) << "part";
    if (old) fs::last_write_time(dir / name, fs::file_time_type::clock::now() - std::chrono::hours(1));
  };
  make(".out.ply.gi-" + dead + "-0.tmp", true);    // removed
  make(".out.ply.gi-" + dead + "-1.tmp", false);   // too young
  make(".out.ply.gi-1-2.tmp", true);               // pid 1 runs
  make(".other.ply.gi-" + dead + "-0.tmp", true);  // another output's: removed too
  make(".out.ply.gi-x-0.tmp", true);               // not one of ours
  make("out.ply.gi-" + dead + "-3.tmp", true);     // not hidden: not ours
  io::writeFileAtomically(p.string(), "new");
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(dir)) left.insert(e.path().filename().string());
  EXPECT_EQ(left, (std::set<std::string>{"out.ply", ".out.ply.gi-" + dead + "-1.tmp", ".out.ply.gi-1-2.tmp",
                                         ".out.ply.gi-x-0.tmp", "out.ply.gi-" + dead + "-3.tmp"}));
  EXPECT_EQ(readAll(p), "new");
  fs::remove_all(dir.parent_path());
}

TEST(AtomicFile, WritesThroughASymbolicLink) {
  const fs::path target = scratch("target.txt"), link = scratch("link.txt");
  io::writeFileAtomically(target.string(), "old");
  fs::create_symlink(target.filename(), link);
  io::writeFileAtomically(link.string(), "new");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(readAll(target), "new");
  EXPECT_EQ(io::cannotCreateBeside(target.string()), "");
  EXPECT_NE(io::cannotCreateBeside((target.parent_path() / "no" / "x").string()), "");
  fs::remove_all(target.parent_path());
}

// A run's outputs change together: a failure on its last file (a full disk)
// left the new PLY over the old one and a PNG without its PFM (an outside
// audit). In a transaction nothing is renamed into place before commit; a
// transaction that ends without one leaves the old files and no temporary.
TEST(AtomicFile, OutputTransactionChangesEveryFileOrNone) {
  const fs::path a = scratch("a.ply"), b = scratch("b.png"), fresh = scratch("new.pfm");
  io::writeFileAtomically(a.string(), "old a");
  io::writeFileAtomically(b.string(), "old b");
  const auto others = [&] {
    size_t n = 0;
    for (const auto& e : fs::directory_iterator(a.parent_path())) n += e.path().filename().string()[0] == '.';
    return n;
  };
  {
    io::OutputTransaction t;
    io::writeFileAtomically(a.string(), "new a");
    io::writeFileAtomically(fresh.string(), "new pfm");
    EXPECT_EQ(readAll(a), "old a");  // held back
    EXPECT_FALSE(fs::exists(fresh));
    EXPECT_THROW(io::writeAtomically(b.string(), [](const std::string& temp) {
                   throw std::runtime_error("cannot write " + temp + ": No space left on device");
                 }),
                 std::runtime_error);
  }  // no commit: the run failed
  EXPECT_EQ(readAll(a), "old a");
  EXPECT_EQ(readAll(b), "old b");
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_EQ(others(), 0u) << "a temporary was left";
  {
    io::OutputTransaction t;
    io::writeFileAtomically(a.string(), "new a");
    io::writeFileAtomically(b.string(), "new b");
    io::writeFileAtomically(fresh.string(), "new pfm");
    t.commit();
  }
  EXPECT_EQ(readAll(a), "new a");
  EXPECT_EQ(readAll(b), "new b");
  EXPECT_EQ(readAll(fresh), "new pfm");
  EXPECT_EQ(others(), 0u);
  io::writeFileAtomically(a.string(), "after");  // no transaction open: written at once
  EXPECT_EQ(readAll(a), "after");
  fs::remove_all(a.parent_path());
}
