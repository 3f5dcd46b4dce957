// shot/available_memory: sizes with suffixes, the SHELLMPM_AVAILABLE_MEMORY override, and a
// figure from /proc on Linux.
#include <catch2/catch.hpp>

#include <cstdlib>

#include "io/user_error.h"
#include "shot/available_memory.h"

using namespace shellmpm;

namespace {

/// Sets an environment variable for the scope, restoring the old value.
struct EnvVar {
  std::string name, old;
  bool had = false;
  EnvVar(const std::string& n, const char* value) : name(n) {
    if (const char* v = std::getenv(n.c_str())) {
      had = true;
      old = v;
    }
    if (value)
      setenv(n.c_str(), value, 1);
    else
      unsetenv(n.c_str());
  }
  ~EnvVar() {
    if (had)
      setenv(name.c_str(), old.c_str(), 1);
    else
      unsetenv(name.c_str());
  }
};

}  // namespace

TEST_CASE("available memory: sizes, the override and /proc", "[available_memory]") {
  CHECK(parse_memory_size("4096") == 4096);
  CHECK(parse_memory_size("2G") == 2.0 * (1 << 30));
  CHECK(parse_memory_size("1.5M") == 1.5 * (1 << 20));
  CHECK(parse_memory_size("3T") == 3.0 * 1024 * 1024 * 1024 * 1024);
  CHECK(parse_memory_size("8GB") < 0);
  CHECK(parse_memory_size("-1") < 0);
  CHECK(parse_memory_size("lots") < 0);
  CHECK(parse_memory_size("") < 0);
  {
    EnvVar e("SHELLMPM_AVAILABLE_MEMORY", "3M");
    const AvailableMemory a = available_memory();
    CHECK(a.known);
    CHECK(a.bytes == 3.0 * (1 << 20));
    CHECK(a.source == "SHELLMPM_AVAILABLE_MEMORY");
  }
  {
    EnvVar e("SHELLMPM_AVAILABLE_MEMORY", "a lot");
    CHECK_THROWS_AS(available_memory(), UserError);
  }
  {
    EnvVar e("SHELLMPM_AVAILABLE_MEMORY", nullptr);
    const AvailableMemory a = available_memory();
    REQUIRE(a.known);  // Linux has /proc/meminfo
    CHECK(a.bytes > 0);
    CHECK(!a.source.empty());
  }
  CHECK(resident_bytes() > 1 << 20);
  CHECK(format_bytes(1536.0 * (1 << 20)) == "1.50 GiB");
  CHECK(format_bytes(320.0 * (1 << 20)) == "320.0 MiB");
}
