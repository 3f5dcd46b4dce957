// Numbers and lists as the scene reader's messages and the scene-format docs print them.
#pragma once
#include <string>
#include <vector>

namespace shellmpm {

/// Shortest text that reads back as the same double ("0.5", "90", "4294967295", "1e-6").
std::string fmt_num(double x);

/// Three significant digits ("0.0417", "1.67e14").
std::string fmt3(double x);

/// fmt_num, but a whole number from 1e6 on as "1e12" when that is shorter (tables).
std::string fmt_bound(double x);

/// The items joined by `sep` ("a, b, c").
std::string join(const std::vector<std::string>& items, const char* sep = ", ");

}  // namespace shellmpm
