// One effect of the step loop. A stage has a name (check and stats.json print it, with
// its time per frame), a rule that says from the scene whether it is needed (a scene
// runs only the effects it calls for), and run(), which reads and writes the shared
// StepContext as its fields' comments say. The registry (registry.h) lists the stages in
// execution order.
//
// Adding an effect: a new stages/<name>.{h,cpp} with a Stage subclass and a static
// `bool needed(const Scene&)`, one line in registry.cpp, and its test.
#pragma once
#include <string_view>

#include "sim/solver/step_context.h"

namespace shellmpm {

class Stage {
 public:
  virtual ~Stage() = default;
  virtual std::string_view name() const = 0;
  virtual void run(StepContext& c) = 0;
};

}  // namespace shellmpm
