// What the Loop basis's two files share (sim/shell/loop_basis.cpp: the regular patches,
// the fans, the basis's set-up and evaluation; loop_local_subdivision.cpp: local
// subdivision of irregular patches): lattice points, fans and Loop's weights.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace shellmpm {
namespace loop_patch {

/// A lattice point of a regular patch: a real vertex (n = 1) or a phantom a + b - c.
struct LatticePoint {
  int n = 0;
  int idx[3] = {-1, -1, -1};
  double w[3] = {0, 0, 0};
};

/// A vertex fan: ring[i], ring[i+1] span face i; `boundary` when the fan is open.
struct FanView {
  const int* ring;
  int size;
  bool boundary;
};

/// If the face with corners c[0..2] (counter-clockwise) is a regular patch, writes its
/// 12 lattice points (Stam's numbering, 0-based) and returns true. See loop_basis.h for
/// the definition of a (boundary-)regular patch and the phantom rule.
bool regular_lattice(const int c[3], const FanView fan[3], LatticePoint P[12]);

/// Loop's beta for valence n.
double loop_beta(int n);

/// Orders the faces around v into a fan. links: (a, b) for each face (v, a, b).
/// Returns an empty string on success, else a description of the problem.
std::string order_fan(const std::vector<std::pair<int, int>>& links, std::vector<int>& ring,
                      std::vector<int>& order, bool& boundary);

}  // namespace loop_patch

// The two files that include this one use these names unqualified.
using loop_patch::FanView;
using loop_patch::LatticePoint;
using loop_patch::loop_beta;
using loop_patch::order_fan;
using loop_patch::regular_lattice;

}  // namespace shellmpm
