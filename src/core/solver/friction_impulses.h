// Coulomb friction at an impact, jointly over a cluster's contacts: the tangential impulses of
// maximal dissipation within each contact's disc, given the normal impulses.
#pragma once

#include <vector>

#include "collision_response/core/simultaneous.h"
#include "solver/contact_forces.h"

namespace collision_response::core {

/// Coulomb friction at an impact whose normal impulses J_k are given (applied already to the
/// bodies' velocities), jointly over the cluster: tangential impulses T_k with |T_k| <= mu J_k
/// that stop every slip they can (sticking), and at mu J_k against the slip that is left where
/// they cannot (sliding), so that friction never reverses a slip and never adds energy: the
/// minimum of the kinetic energy left over the discs |T_k| <= mu J_k. It is solved block by block
/// (contacts connected through shared movable bodies; exact), in long double: a block of up to
/// 128 contacts by dense algebra, a larger one iteratively to a projected-gradient residual of
/// 1e-12 of its largest slip (`converged` false where a block stops short of it: the bounds and
/// the energy still hold). Nothing depends on the order of the contacts (doc/model.md, "Work per
/// message, and threads"). Returns the impulses (tangential, on b) and modes per contact, and per
/// body the change of velocity (in `acceleration`) and of angular velocity (in
/// `angular_acceleration`).
///
/// `work` (optional) bounds and counts the solve's work, in contact iterations: a block of n
/// contacts solved iteratively counts n an iteration, one solved densely 1 + n^2 / 4 + n^3 / 400
/// a factorisation of its matrix (a Newton step, a round of polishing). With a limit, a block's
/// solve stops where its next step would pass it, its impulses then within the bounds and adding
/// no energy (the lowest energy reached iteratively, the barrier's last iterate densely, else
/// none), and a block reached with the limit spent gets no friction; `cut` says so.
ContactForceSolution solveFrictionImpulses(const std::vector<ForceBody>& bodies,
                                           const std::vector<ForceContact>& contacts,
                                           const std::vector<double>& normal_impulses,
                                           WorkBound* work = nullptr);

}  // namespace collision_response::core
