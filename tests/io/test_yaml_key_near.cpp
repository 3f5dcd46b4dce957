// yaml_key_near_line (io/yaml_key_near.h): the key a line belongs to, from indentation.
#include <catch2/catch.hpp>

#include "io/yaml_key_near.h"

using namespace shellmpm;

TEST_CASE("yaml_key_near_line names the key path of a line from indentation", "[scene]") {
  const std::string text =
      "version: 1\n"                   // 1
      "shot:\n"                        // 2
      "  frames: [1, 2\n"              // 3
      "  # a comment\n"                // 4
      "materials:\n"                   // 5
      "  - name: a\n"                  // 6
      "    type: sand\n"               // 7
      "  - name: b\n"                  // 8
      "    shape: {type: box}\n"       // 9
      "    color:\n"                   // 10
      "      - 0.5\n"                  // 11
      "shells:\n"                      // 12
      "- name: s\n"                    // 13  (items at the key's own column)
      "  pins:\n"                      // 14
      "    - box: {min: [0, 0, 0]}\n"  // 15
      "    - indices: [1]\n"           // 16
      "\"quoted key\": 3\n";           // 17
  CHECK(yaml_key_near_line(text, 0).empty());
  CHECK(yaml_key_near_line(text, 1) == "version");
  CHECK(yaml_key_near_line(text, 2) == "shot");
  CHECK(yaml_key_near_line(text, 3) == "shot.frames");
  CHECK(yaml_key_near_line(text, 4) == "shot.frames");  // comments do not count
  CHECK(yaml_key_near_line(text, 6) == "materials[0].name");
  CHECK(yaml_key_near_line(text, 7) == "materials[0].type");
  CHECK(yaml_key_near_line(text, 8) == "materials[1].name");
  CHECK(yaml_key_near_line(text, 9) == "materials[1].shape");
  CHECK(yaml_key_near_line(text, 11) == "materials[1].color[0]");
  CHECK(yaml_key_near_line(text, 13) == "shells[0].name");
  CHECK(yaml_key_near_line(text, 15) == "shells[0].pins[0].box");
  CHECK(yaml_key_near_line(text, 16) == "shells[0].pins[1].indices");
  CHECK(yaml_key_near_line(text, 17) == "quoted key");
  CHECK(yaml_key_near_line("# only a comment\n{{{\n", 2).empty());
  CHECK(yaml_key_near_line("a:\n  b: 1\n\tc: 2\n", 3) == "a.b");  // a tab is not a key
}
