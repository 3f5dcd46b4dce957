// The review page `batch collect` writes: self-contained (no http, no file references),
// opened in headless Chromium (Debian's `chromium`): a screenshot is taken, every image
// loads and every task is on the page. Skipped, with a message, where chromium is missing.
#include <catch2/catch.hpp>
#include <filesystem>
#include <regex>
#include <string>

#include "farm/review_page.h"
#include "tests/app/cli_harness.h"
#include "tests/farm/farm_fixtures.h"

namespace fs = std::filesystem;
using namespace shellmpm_test;

TEST_CASE("review page: base64 data URIs", "[farm][review]") {
  CHECK(shellmpm::data_uri("text/plain", "") == "data:text/plain;base64,");
  CHECK(shellmpm::data_uri("text/plain", "f") == "data:text/plain;base64,Zg==");
  CHECK(shellmpm::data_uri("text/plain", "fo") == "data:text/plain;base64,Zm8=");
  CHECK(shellmpm::data_uri("text/plain", "foo") == "data:text/plain;base64,Zm9v");
  CHECK(shellmpm::data_uri("a/b", std::string("\xff\x00\x10", 3)) == "data:a/b;base64,/wAQ");
}

TEST_CASE("review page: headless Chromium loads every image and shows every task",
          "[farm][review]") {
  std::string chromium;
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (fs::exists(p)) chromium = p;
  if (chromium.empty()) {
    WARN("skipped: chromium is not installed (sh tools/install-deps.sh installs it)");
    return;
  }
  TempDir d("farm_review");
  write_jelly(d, 3);
  const std::string batch =
      d.write("b.yaml", two_by_two_batch(3, "    preview: {size: 96x64, renderer: raster}\n"));
  const CmdResult run = run_shellmpm("batch run -q " + batch);
  INFO(run.output);
  REQUIRE(run.code == 0);
  REQUIRE(run_shellmpm("batch collect -q " + batch).code == 0);
  const std::string page = d.file("out/review.html");
  const std::string html = read_text(page);
  // Self-contained: no link to a server or a file beside it.
  CHECK(html.find("http://") == html.find("http://www.w3.org/2000/svg"));
  CHECK(html.find("https://") == std::string::npos);
  CHECK(html.find("src=\"file:") == std::string::npos);
  CHECK(html.find("src=\"data:image/png;base64,") != std::string::npos);
  CHECK(html.find("src=\"data:video/mp4;base64,") != std::string::npos);

  const std::string flags =
      " --headless --no-sandbox --disable-gpu --no-first-run "
      "--user-data-dir=" +
      d.file("chromium") + " --window-size=1400,1200 ";
  const std::string shot = d.file("shot.png");
  const CmdResult s =
      run_command("timeout 120 " + chromium + flags + "--screenshot=" + shot + " file://" + page);
  INFO(s.output);
  REQUIRE(fs::exists(shot));
  CHECK(fs::file_size(shot) > 20000);  // a rendered page, not a blank one
  // The page after its load handler ran: it counts the images that decoded.
  const CmdResult dom =
      run_command("timeout 120 " + chromium + flags + "--dump-dom file://" + page + " 2>/dev/null");
  std::smatch m;
  const std::regex body(
      "<body data-images=\"([0-9]+)\" data-loaded=\"([0-9]+)\" "
      "data-tasks=\"([0-9]+)\">");
  REQUIRE(std::regex_search(dom.output, m, body));
  CHECK(m[1] == "4");  // four contact sheets
  CHECK(m[2] == m[1]);
  CHECK(m[3] == "4");
  for (const char* id : {"velocity-0_0_0", "velocity-0_-1_0"})
    CHECK(dom.output.find(id) != std::string::npos);
  CHECK(dom.output.find("images: 4 of 4 loaded") != std::string::npos);
}
