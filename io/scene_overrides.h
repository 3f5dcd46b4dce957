// `--set KEY=VALUE` overrides: the key path is walked through the document with the schema
// (so an unknown key or a list index out of range is an error naming the override), and
// the value, parsed as YAML, replaces the whole value at that key before validation.
#pragma once
#include <string>

#include "io/scene_document.h"

namespace shellmpm::scenefile {

/// Applies one "a.b[0].c=value" override to the document.
/// @throws UserError at "--set a.b[0].c=value" for a bad path or a value that is not one
///   plain YAML value (with the quoted form to use instead).
void apply_override(DocNode& root, const std::string& ov);

}  // namespace shellmpm::scenefile
