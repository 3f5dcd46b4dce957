// `shellmpm check` on contact scenes: contact parameters per shell, and a warning when
// the control mesh spacing is far from dx.
#include <catch2/catch.hpp>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

TEST_CASE("CLI: check reports contact and warns when the mesh spacing is far from dx", "[cli]") {
  const std::string scene = std::string(SHELLMPM_SOURCE_DIR) + "/scenes/cloth_drape.yaml";
  const CmdResult ok = run_shellmpm("check " + scene);
  INFO(ok.output);
  CHECK(ok.code == 0);
  CHECK(ok.output.find("contact: 3200 contact particles") != std::string::npos);
  CHECK(ok.output.find("warning") == std::string::npos);
  const CmdResult fine = run_shellmpm("check " + scene + " --set shot.dx=0.01");
  INFO(fine.output);
  CHECK(fine.code == 0);
  CHECK(fine.output.find("warning: shell cloth: its mesh spacing") != std::string::npos);
  CHECK(fine.output.find("much coarser") != std::string::npos);
}
