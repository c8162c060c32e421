// What the peer engines share: coefficients for the engines that multiply two bodies' own.
#include <cmath>

#include "harness.h"

namespace collision_response::bench {

ProductRestitutions productRestitutions(const core::Scene& scene) {
  // Where all balls share one material, balls get sqrt(e_ball-ball) and obstacles
  // e_ball-obstacle / sqrt(e_ball-ball), so that every product is the scene's coefficient; where
  // they do not (the drop test: its balls never meet), each ball gets its coefficient against
  // the obstacles (all of one material) and the obstacles 1.
  const std::string& ball_material = scene.bodies.front().material;
  bool one_material = true;
  for (const core::BodySpec& spec : scene.bodies) {
    one_material = one_material && spec.material == ball_material;
  }
  const std::string& obstacle_material =
      scene.obstacles.empty() ? ball_material : scene.obstacles.front().material;
  const double ball_ball = *scene.materials.restitution(ball_material, ball_material);
  ProductRestitutions product;
  for (const core::BodySpec& spec : scene.bodies) {
    product.bodies.push_back(one_material
                                 ? std::sqrt(ball_ball)
                                 : *scene.materials.restitution(spec.material, obstacle_material));
  }
  for (const core::ObstacleSpec& spec : scene.obstacles) {
    product.obstacles.push_back(one_material
                                    ? *scene.materials.restitution(ball_material, spec.material) /
                                          std::sqrt(ball_ball)
                                    : 1.0);
  }
  return product;
}

}  // namespace collision_response::bench
