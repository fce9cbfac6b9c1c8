// ParaView's own XDMF reader opens a snapshot file written by `capsim run`: a small case with
// snapshots, then pvbatch on tests/solver/io/open_snapshots.py, which checks the time steps, points, cells
// and point arrays (q_n, q, velocity, tau_min, tau_max) against case.h5 and renders one image offscreen.
// Label `paraview` (not in the default suite): needs `pvbatch`, and `xvfb-run` where there is no $DISPLAY
// (scripts/setup-paraview installs both); skipped without them.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "solver/mesh/mesh.h"

namespace {

namespace fs = std::filesystem;

struct Cmd {
  int code = -1;
  std::string out;
};

// Runs `cmd` through the shell with stderr folded into stdout; returns the exit code and the output.
Cmd sh(const std::string& cmd, const fs::path& log) {
  const std::string full = "(" + cmd + ") >" + log.string() + " 2>&1";
  const int st = std::system(full.c_str());
  Cmd r;
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  r.out = ss.str();
  return r;
}

TEST(ParaView, XdmfReaderOpensTheSnapshotsAndRendersThem) {
  const fs::path dir = fs::path(CAPSIM_TEST_TMP) / "paraview";
  fs::remove_all(dir);
  fs::create_directories(dir);
  if (sh("command -v pvbatch", dir / "which.log").code != 0)
    GTEST_SKIP() << "pvbatch not found (install ParaView with scripts/setup-paraview)";
  // Debian's ParaView renders through X even offscreen: without a display, use a virtual one.
  const char* display = std::getenv("DISPLAY");
  std::string launcher;
  if (display == nullptr || *display == '\0') {
    if (sh("command -v xvfb-run", dir / "which_xvfb.log").code != 0)
      GTEST_SKIP() << "no $DISPLAY and no xvfb-run for pvbatch to render on (scripts/setup-paraview installs it)";
    launcher = "xvfb-run -a ";
  }

  // A prolate capsule at level 1 for a few tenths of a time unit: four snapshots (t = 0, 0.1, 0.2, 0.3
  // at most) of a deforming membrane, in seconds.
  const int level = 1;
  const double aspect_ratio = 2.0;
  const fs::path case_toml = dir / "case.toml";
  std::ofstream(case_toml) << "[capsule]\naspect_ratio = " << aspect_ratio << "\nlaw = \"skalak\"\n"
                           << "[flow]\ncapillary_number = 0.3\n[mesh]\nlevel = " << level << "\n"
                           << "[time]\nt_end = 0.35\n[output]\nsnapshot_interval = 0.1\n";
  const fs::path out = dir / "run";
  const Cmd run = sh(std::string(CAPSIM_EXE_PATH) + " run " + case_toml.string() + " --out " + out.string() +
                         " --threads 1",
                     dir / "run.log");
  ASSERT_EQ(run.code, 0) << run.out;
  ASSERT_TRUE(fs::exists(out / "case.xmf")) << run.out;

  const auto mesh = capsim::mesh::make_capsule_mesh(level, aspect_ratio);
  const fs::path png = dir / "snapshot.png";
  const std::string script = std::string(CAPSIM_SOURCE_DIR) + "/tests/solver/io/open_snapshots.py";
  // --force-offscreen-rendering: no window is shown (the X server, real or virtual, only hosts the context).
  const Cmd pv = sh(launcher + "pvbatch --force-offscreen-rendering " + script + " " + out.string() + " " +
                        std::to_string(mesh.num_nodes()) + " " + std::to_string(mesh.num_elements()) + " " +
                        png.string(),
                    dir / "pvbatch.log");
  EXPECT_EQ(pv.code, 0) << pv.out;
  ASSERT_TRUE(fs::exists(png)) << pv.out;
  // A PNG, and not an empty one (the script checks the pixels).
  std::ifstream img(png, std::ios::binary);
  char sig[8] = {};
  img.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  EXPECT_GT(fs::file_size(png), 1000u);
}

}  // namespace
