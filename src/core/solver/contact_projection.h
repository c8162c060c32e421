// Lasting contact's velocities and positions made consistent with its contacts: the least
// change (impulses, displacements) that closes every contact's normal relative velocity (and a
// sticking one's slip) or gap.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "solver/contact_forces.h"

namespace collision_response::core {

/// Velocities consistent with lasting contact: the smallest change of the bodies' motion (impulses
/// of least norm) after which every contact's normal relative velocity is 0 and, where
/// `sticking[k]`, its slip too. Applied to the bodies' velocity and angular_velocity.
void closeContactVelocities(std::vector<ForceBody>& bodies,
                            const std::vector<ForceContact>& contacts,
                            const std::vector<bool>& sticking);

/// Positions consistent with lasting contact: the smallest displacements (mass-weighted, along the
/// normals) that close each contact's gap to `gaps[k]` less itself, that is to 0 (pass the gaps
/// the contacts have). Applied to `positions` of the movable bodies.
void closeContactGaps(std::vector<Eigen::Vector3d>& positions, const std::vector<ForceBody>& bodies,
                      const std::vector<ForceContact>& contacts, const std::vector<double>& gaps);

}  // namespace collision_response::core
