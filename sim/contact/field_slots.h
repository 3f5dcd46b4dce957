// The shells' own velocity fields inside the implicit grid step (shell_fields.h,
// grid_step.h).
//
// Explicitly, a shell's forces go into its own field's momentum before Bardenhagen's rule
// meets the bodies at a shared node, and the grid update then adds the same velocity change
// to all of them. In one implicit solve over a single velocity per node, the bodies at a
// shared node move together inside the solve (a stiff can's forces pushed the sand beside
// it) and their fields' relative velocities came on top after it: motion the solve had not
// minimised over, so a steel can resting on sand kept straining and yielding at rest, and
// its crush after lift-off depended on the step (14% between 1/240 s and 1/2400 s).
//
// Here the rule's outcome is taken into the solve. Before it, the bodies at each shared
// node are grouped: those the rule brought together (approaching: they share the normal
// velocity and their tangential slip is Coulomb's, as explicitly) form one group and move
// with one unknown velocity, each with its fixed offset from it (the rule's result); bodies
// the rule left apart are in different groups and move independently. The group with the
// bulk material (or, without it, the first shell's) moves with the node's own unknown u,
// every other group with an unknown of its own, a slot. Each group's mass term is
// M |U - U^*|^2 / 2 with M its bodies' mass and U^* their momentum less their offsets, so the
// rule's momentum exchange is kept. Bulk material and contact particles read u; a shell's
// control points read its group's unknown plus its offset. Nodes that keep one velocity
// (walls, colliders) and nodes under a collider gate keep today's treatment. After a solve,
// groups whose solved velocities close on each other faster than their gap allows are
// joined and the step is solved again (ShellFields::regroup, up to three times).
#pragma once
#include <cstdint>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

struct FieldSlots {
  /// Shared nodes whose base group replaces the node's mass and velocity in the solve:
  /// global node index (g kBlockNodes + n), the group's mass [kg] and target velocity [m/s].
  std::vector<std::uint32_t> base_node;
  std::vector<Real> base_m;
  std::vector<Vec3> base_v;
  /// Slots: the node each one sits at, its group's mass and target velocity.
  std::vector<std::uint32_t> slot_node;
  std::vector<Real> slot_m;
  std::vector<Vec3> slot_v;
  /// Per slot, the velocity of its group's first body (the rule's outcome): after a
  /// regroup, the solved velocity the step's next solve starts from.
  std::vector<Vec3> slot_start;
  /// Per grid shell: per global node its slot there, -1 for the node's u (empty: the shell
  /// has no slot anywhere).
  std::vector<std::vector<int>> slot_of;
  /// Per grid shell, per control point: sum_n w_n o_n, its offsets from its groups'
  /// velocities over its stencil [m/s].
  std::vector<std::vector<Vec3>> control;

  std::size_t num_slots() const { return slot_node.size(); }
  bool empty() const { return base_node.empty() && slot_node.empty(); }
};

}  // namespace shellmpm
