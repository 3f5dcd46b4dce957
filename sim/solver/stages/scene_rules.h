// What a scene switches on, read from the scene alone: the stages' `needed` rules and
// the solver's set-up use the same answers.
#pragma once
#include <cstddef>

#include "sim/implicit/newton.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// Shell i has contact (its control points live on the grid): contact `on`, or `auto`
/// with something to touch (a collider, bulk material or another shell).
bool shell_has_contact(const Scene& s, std::size_t i);
/// Some shell has contact.
bool any_contact_shell(const Scene& s);
/// Some shell has no contact (integrates directly, no grid).
bool any_direct_shell(const Scene& s);
/// The grid is needed: bulk sources or a contact shell.
bool grid_needed(const Scene& s);
/// Some bulk material has plasticity (sand, snow).
bool any_plastic_material(const Scene& s);
/// Some shell material dents (yield stress > 0).
bool any_denting_shell(const Scene& s);
/// Some source emits continuously.
bool any_emitting_source(const Scene& s);

/// The Newton settings shot.integrator implicit asks for.
NewtonOptions newton_options(const ShotSettings& s);

}  // namespace shellmpm
