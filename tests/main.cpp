#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>

#include "sim/core/lsan_suppressions.h"
