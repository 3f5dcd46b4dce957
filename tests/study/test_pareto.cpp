// The Pareto front of (cost, |error|).
#include <catch2/catch.hpp>

#include "study/study_runner.h"

using namespace shellmpm;

namespace {

StudyRun run(double cost, double error, const std::string& status = "ok") {
  StudyRun r;
  r.cost = cost;
  r.error = error;
  r.status = status;
  return r;
}

}  // namespace

TEST_CASE("mark_pareto_front keeps exactly the undominated runs", "[study]") {
  std::vector<StudyRun> runs = {run(1, 0.10), run(2, -0.05),           run(3, 0.07),
                                run(4, 0.01), run(0.5, 0.5, "failed"), run(2, 0.05)};
  mark_pareto_front(runs);
  CHECK(runs[0].pareto);        // cheapest
  CHECK(runs[1].pareto);        // |error| counts, not its sign
  CHECK_FALSE(runs[2].pareto);  // dearer and worse than runs[1]
  CHECK(runs[3].pareto);        // most accurate
  CHECK_FALSE(runs[4].pareto);  // failed runs are never on it
  CHECK(runs[5].pareto);        // a tie with runs[1]: neither dominates the other
}
