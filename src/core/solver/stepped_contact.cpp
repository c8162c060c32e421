#include "solver/stepped_contact.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

#include "solver/effective_mass.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// A sub-step that ends earlier than this fraction of its duration makes no headway: the
/// cluster is held instead of being solved again and again at nearly one instant.
constexpr double kShortestSubstep = 1.0 / 64;

/// MPRGP's Gamma: a proportioning step (releasing bound impulses) is taken when the chopped
/// gradient is this many times the reduced free one. Dostal's theory takes 1; on the settling
/// piles of the accuracy benchmark 1 and 10 needed about 2,000 iterations a solve on average
/// (100 balls) and often failed within 20,000, 100 needed about 300.
constexpr double kProportioning = 100;

/// The coupling of a set of contacts, A = N W N^T (W the inverse masses; a sphere's normal
/// impulse passes through its centre, so it does not turn it), applied as an operator: the
/// impulses' velocity changes on each body, then each contact's normal relative velocity. The
/// contacts are taken in the order given, every sum in that order.
class ContactSpace {
 public:
  ContactSpace(const std::vector<SteppedBody>& bodies, const std::vector<SteppedContact>& contacts,
               const std::vector<std::size_t>& order)
      : change_(bodies.size()) {
    // What the operator reads of each contact, compact and in the solve's order: the solves
    // apply it hundreds of times, and a contact's full record would be read each time.
    rows_.reserve(order.size());
    for (const std::size_t k : order) {
      const SteppedContact& c = contacts[k];
      rows_.push_back(Row{c.a, c.b, bodies[c.a].inverse_mass, bodies[c.b].inverse_mass, c.normal});
    }
    std::vector<double> reach(bodies.size(), 0.0);  // sum over a body's contacts of w |n.n|
    for (const Row& row : rows_) {
      reach[row.a] += row.inverse_mass_a;
      reach[row.b] += row.inverse_mass_b;
    }
    // Gershgorin: |A| <= max_k sum_l |A_kl| <= max_k (reach_a + reach_b).
    for (const Row& row : rows_) norm_bound_ = std::max(norm_bound_, reach[row.a] + reach[row.b]);
  }

  Eigen::Index size() const { return static_cast<Eigen::Index>(rows_.size()); }
  double normBound() const { return norm_bound_; }

  /// Each body's velocity change from the impulses x (in the order of the contacts).
  const std::vector<Eigen::Vector3d>& velocityChanges(const Eigen::VectorXd& x) const {
    std::fill(change_.begin(), change_.end(), Eigen::Vector3d::Zero());
    for (Eigen::Index i = 0; i < size(); ++i) {
      const Row& row = rows_[static_cast<std::size_t>(i)];
      change_[row.a] -= (row.inverse_mass_a * x[i]) * row.normal;
      change_[row.b] += (row.inverse_mass_b * x[i]) * row.normal;
    }
    return change_;
  }

  /// y = A x.
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    const std::vector<Eigen::Vector3d>& change = velocityChanges(x);
    y.resize(size());
    for (Eigen::Index i = 0; i < size(); ++i) {
      const Row& row = rows_[static_cast<std::size_t>(i)];
      y[i] = row.normal.dot(change[row.b] - change[row.a]);
    }
  }

  /// Each contact's normal relative velocity (> 0 opening) under the velocities `v`.
  Eigen::VectorXd normalVelocities(const std::vector<Eigen::Vector3d>& v) const {
    Eigen::VectorXd d(size());
    for (Eigen::Index i = 0; i < size(); ++i) {
      const Row& row = rows_[static_cast<std::size_t>(i)];
      d[i] = row.normal.dot(v[row.b] - v[row.a]);
    }
    return d;
  }

  /// v += the velocity changes of the impulses x.
  void addVelocityChanges(const Eigen::VectorXd& x, std::vector<Eigen::Vector3d>& v) const {
    const std::vector<Eigen::Vector3d>& change = velocityChanges(x);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] += change[i];
  }

 private:
  struct Row {
    std::size_t a, b;
    double inverse_mass_a, inverse_mass_b;
    Eigen::Vector3d normal;
  };
  std::vector<Row> rows_;
  mutable std::vector<Eigen::Vector3d> change_;
  double norm_bound_ = 0.0;
};

struct BoundedSolution {
  Eigen::VectorXd impulses;
  bool converged = false;
  int iterations = 0;
};

/// One run of MPRGP over a contact space: the impulses x, the gradient g = Ax + q at x with its
/// free, chopped and reduced free parts, and the search direction p.
class Mprgp {
 public:
  Mprgp(const ContactSpace& space, const Eigen::VectorXd& q, Eigen::VectorXd& x)
      : space_(space),
        q_(q),
        x_(x),
        step_(1.9 / space.normBound()),
        free_(space.size()),
        chopped_(space.size()),
        reduced_(space.size()) {}

  /// The gradient computed afresh at x (the recurrences drift by rounding), and split.
  void refresh() {
    space_.apply(x_, g_);
    g_ += q_;
    split();
  }

  /// The search direction starts again along the free gradient.
  void restartDirection() { p_ = free_; }

  /// The largest component of the projected gradient: of its free part, and of the negative part
  /// of its bound one.
  double residual() const {
    return std::max(free_.lpNorm<Eigen::Infinity>(), chopped_.lpNorm<Eigen::Infinity>());
  }

  /// Whether x is proportional: the chopped gradient is not kProportioning times the reduced free
  /// one (then the free components are minimised on, else the bound ones released).
  bool proportional() const {
    return chopped_.squaredNorm() <= kProportioning * kProportioning * reduced_.dot(free_);
  }

  /// A conjugate gradient step along p, or, where it would leave x >= 0, an expansion: to the
  /// bound along p, then a projected gradient step. False on a direction of no curvature and no
  /// bound.
  bool conjugateGradientStep() {
    space_.apply(p_, ap_);
    const double curvature = p_.dot(ap_);
    // The longest step keeping x >= 0: the least x_i / p_i where p_i > 0 (a local, so that the
    // running least stays in a register).
    double feasible = std::numeric_limits<double>::infinity();
    const double* x = x_.data();
    const double* p = p_.data();
    for (Eigen::Index i = 0; i < space_.size(); ++i) {
      if (p[i] > 0) {
        const double ratio = x[i] / p[i];
        if (ratio < feasible) feasible = ratio;
      }
    }
    const double conjugate = curvature > 0 ? g_.dot(p_) / curvature : feasible;
    if (!std::isfinite(conjugate)) return false;
    if (conjugate <= feasible) {
      x_ = (x_ - conjugate * p_).cwiseMax(0.0);
      g_ -= conjugate * ap_;
      split();
      p_ = free_ - (curvature > 0 ? free_.dot(ap_) / curvature : 0.0) * p_;
    } else {
      x_ = (x_ - feasible * p_).cwiseMax(0.0);
      g_ -= feasible * ap_;
      split();
      x_ = (x_ - step_ * free_).cwiseMax(0.0);
      refresh();
      p_ = free_;
    }
    return true;
  }

  /// Proportioning: the bound components whose gradient points inside released. False where the
  /// chopped gradient meets no curvature.
  bool proportioningStep() {
    space_.apply(chopped_, ap_);
    const double curvature = chopped_.dot(ap_);
    if (!(curvature > 0)) return false;
    const double length = g_.dot(chopped_) / curvature;
    x_ = (x_ - length * chopped_).cwiseMax(0.0);
    g_ -= length * ap_;
    split();
    p_ = free_;
    return true;
  }

 private:
  /// The free, chopped and reduced free gradients at x.
  void split() {
    for (Eigen::Index i = 0; i < space_.size(); ++i) {
      const bool is_free = x_[i] > 0;
      free_[i] = is_free ? g_[i] : 0.0;
      chopped_[i] = is_free ? 0.0 : std::min(g_[i], 0.0);
      reduced_[i] = is_free ? std::min(x_[i] / step_, g_[i]) : 0.0;
    }
  }

  const ContactSpace& space_;
  const Eigen::VectorXd& q_;
  Eigen::VectorXd& x_;
  const double step_;  // the gradient projection's fixed step
  Eigen::VectorXd g_, ap_, free_, chopped_, reduced_, p_;
};

/// min 1/2 x'Ax + q'x over x >= 0 (the complementarity problem x >= 0, Ax + q >= 0,
/// x'(Ax + q) = 0), by MPRGP (header), from `start`, until every component of the projected
/// gradient is within `tolerance` (its free components, and the negative part of the bound ones).
/// Not converged when an impulse passes `runaway` (the problem has no solution: the minimum is
/// unbounded) or the iterations run out.
BoundedSolution solveBounded(const ContactSpace& space, const Eigen::VectorXd& q,
                             const Eigen::VectorXd& start, double tolerance, int max_iterations,
                             double runaway) {
  BoundedSolution result;
  Eigen::VectorXd& x = result.impulses;
  x = start.cwiseMax(0.0);
  if (space.size() == 0) {
    result.converged = true;
    return result;
  }
  Mprgp mprgp(space, q, x);
  mprgp.refresh();
  mprgp.restartDirection();
  for (; result.iterations < max_iterations; ++result.iterations) {
    if (mprgp.residual() <= tolerance) {
      // Confirmed on a fresh gradient: the recurrences drift by rounding.
      mprgp.refresh();
      if (mprgp.residual() <= tolerance) {
        result.converged = true;
        return result;
      }
      mprgp.restartDirection();
    }
    const bool went_on =
        mprgp.proportional() ? mprgp.conjugateGradientStep() : mprgp.proportioningStep();
    if (!went_on) break;
    if (result.iterations % 64 == 63) {
      mprgp.refresh();
      if (x.maxCoeff() > runaway) break;
    }
  }
  return result;
}

/// The movable bodies' kinetic energy at the velocities `v` (J).
double kineticEnergy(const std::vector<SteppedBody>& bodies,
                     const std::vector<Eigen::Vector3d>& v) {
  double energy = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass > 0) energy += 0.5 * v[i].squaredNorm() / bodies[i].inverse_mass;
  }
  return energy;
}

/// The solve's order of the contacts: by their points (then normals), which no name and no
/// listing order of the bodies changes; two contacts at one point and along one normal (only
/// between overlapping bodies) keep the order they were given in.
std::vector<std::size_t> contactOrder(const std::vector<SteppedContact>& contacts,
                                      const std::vector<char>& selected) {
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (selected[k]) order.push_back(k);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    const SteppedContact& p = contacts[x];
    const SteppedContact& r = contacts[y];
    return std::tie(p.point.x(), p.point.y(), p.point.z(), p.normal.x(), p.normal.y(),
                    p.normal.z()) < std::tie(r.point.x(), r.point.y(), r.point.z(), r.normal.x(),
                                             r.normal.y(), r.normal.z());
  });
  return order;
}

/// Stage 3 (header): the impulses that keep every gap of `order` at the sub-step's end, added to
/// `v`; `warm` in the solve's order. The gap at the end, gap + d' h, is asked to be at least
/// twice the residual the solve is allowed (so that the solved gaps stay open sub-step after
/// sub-step: a gap allowed to close by the residual each time would ratchet into an overlap),
/// which is within the touching band; an overlap deeper than the band (states given so) is held
/// and opened by as little. Where bodies are wedged (a row of balls spanning a box exactly), no
/// velocities open every gap: the solve does not converge, or its impulses run away, and the
/// gaps are then only kept from closing (every target <= 0, which velocities 0 meet).
BoundedSolution keepGaps(const std::vector<SteppedBody>& bodies,
                         const std::vector<SteppedContact>& contacts,
                         const std::vector<std::size_t>& order, const Eigen::VectorXd& warm,
                         double duration, double tolerance, int max_iterations, int total_left,
                         std::vector<Eigen::Vector3d>& v) {
  const ContactSpace space(bodies, contacts, order);
  const Eigen::VectorXd d = space.normalVelocities(v);
  Eigen::VectorXd opening(space.size());  // (target - gap) / h
  for (Eigen::Index i = 0; i < space.size(); ++i) {
    const SteppedContact& c = contacts[order[static_cast<std::size_t>(i)]];
    const double target = c.gap >= -c.band ? 0.0 : c.gap;
    opening[i] = (target - c.gap) / duration;
  }
  // Impulses past this are running away (no velocities meet the targets): the momentum the
  // bodies carry, and what the targets ask, a thousand times over.
  double momentum = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass > 0) momentum += v[i].norm() / bodies[i].inverse_mass;
  }
  double lightest = std::numeric_limits<double>::infinity();
  for (const SteppedBody& body : bodies) {
    if (body.inverse_mass > 0) lightest = std::min(lightest, 1.0 / body.inverse_mass);
  }
  const double runaway = 1e3 * (momentum + lightest * opening.cwiseAbs().sum());
  BoundedSolution solution = solveBounded(space, d - opening, warm, tolerance,
                                          std::min(max_iterations, total_left), runaway);
  if (!solution.converged) {
    const int spent = solution.iterations;
    solution = solveBounded(space, d - opening.cwiseMin(0.0), warm.cwiseMin(runaway), tolerance,
                            std::max(0, std::min(max_iterations, total_left - spent)),
                            std::numeric_limits<double>::infinity());
    solution.iterations += spent;
  }
  space.addVelocityChanges(solution.impulses, v);
  return solution;
}

/// The outcome the stages fill in: the sub-step's duration, a record per contact, and each
/// participant's velocities at the start (which the stages change).
SteppedOutcome startingOutcome(const std::vector<SteppedBody>& bodies, std::size_t contacts,
                               double duration) {
  SteppedOutcome outcome;
  outcome.duration = duration;
  outcome.contacts.resize(contacts);
  for (const SteppedBody& body : bodies) {
    outcome.velocity.push_back(body.velocity);
    outcome.angular_velocity.push_back(body.angular_velocity);
  }
  return outcome;
}

/// The residual allowed of every solve (m/s): over the sub-step, a quarter of the tightest band.
double solveTolerance(const std::vector<SteppedContact>& contacts, double duration) {
  double tolerance = std::numeric_limits<double>::infinity();
  for (const SteppedContact& c : contacts)
    tolerance = std::min(tolerance, 0.25 * c.band / duration);
  return tolerance;
}

/// Which contacts touch at the start and which of them strike, with the speed each striking one
/// leaves at and what the sub-step before took from the arrivals (J).
struct Strikes {
  std::vector<char> touching;
  std::vector<double> bounce_speed;
  bool any = false;
  double owed = 0.0;
};

/// A sphere's side of a contact whose point is along `outward` from its centre: its lever arm
/// R outward, for the effective mass (solver/effective_mass.h).
ContactSide sphereSide(const SteppedBody& body, const Eigen::Vector3d& outward) {
  return {body.inverse_mass, sphereInverseInertia(body.inverse_mass, body.spin_factor, body.radius),
          body.radius * outward};
}

/// The strikes of stage 1 (header), each contact's approach speed and whether it struck recorded
/// in `outcome`.
Strikes findStrikes(const std::vector<SteppedBody>& bodies,
                    const std::vector<SteppedContact>& contacts, const SteppedSettings& settings,
                    SteppedOutcome& outcome) {
  const double h = settings.duration;
  const std::vector<Eigen::Vector3d>& v = outcome.velocity;
  Strikes strikes;
  strikes.touching.assign(contacts.size(), 0);
  strikes.bounce_speed.assign(contacts.size(), 0.0);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const SteppedContact& c = contacts[k];
    SteppedContactOutcome& out = outcome.contacts[k];
    out.approach_speed = c.normal.dot(v[c.a] - v[c.b]);
    strikes.touching[k] = c.gap <= c.band;
    const double speed = std::max(out.approach_speed, c.arrival_speed);
    // A bounce slower than sqrt(2 g band) would not leave the touching band under gravity g
    // (the exact model's rest rule, restSpeed in motion.h): it rests, and the gap keeping
    // stops it. What the solves leave behind (their residual) is far slower than that.
    const double gravity = std::max(bodies[c.a].kick.norm(), bodies[c.b].kick.norm()) / h;
    const double rounding =
        64 * kEps * (v[c.a].lpNorm<Eigen::Infinity>() + v[c.b].lpNorm<Eigen::Infinity>());
    out.struck = strikes.touching[k] && speed > rounding &&
                 speed > std::sqrt(2 * gravity * c.band) && speed >= settings.restitution_threshold;
    if (out.struck) {
      strikes.bounce_speed[k] = c.restitution * speed;
      const double closing = std::max(out.approach_speed, 0.0);
      // (1/2) m_eff (speed^2 - closing^2), m_eff = 1 / n.K.n (w_a + w_b to the bit for spheres).
      strikes.owed += 0.5 * (speed * speed - closing * closing) /
                      inverseEffectiveMassAlong(sphereSide(bodies[c.a], c.normal),
                                                sphereSide(bodies[c.b], -c.normal), c.normal);
    }
    strikes.any = strikes.any || out.struck;
  }
  return strikes;
}

/// The kinetic energy with the restitution impulses J scaled by s: K(s) = K_c + s X + s^2 R / 2
/// (X = J.d after compression, R = J.AJ). With one coefficient and no arrival it is below the
/// energy before (Newton's law for one contact; jointly it need not be); s is the largest in
/// [0, 1] with K(s) <= the energy `before` plus what the sub-step before took from the arrivals
/// (`owed`). `v`: the velocities after compression.
double restitutionScale(const std::vector<SteppedBody>& bodies, const ContactSpace& space,
                        const Eigen::VectorXd& restitution, const std::vector<Eigen::Vector3d>& v,
                        double before, double owed) {
  Eigen::VectorXd a_restitution;
  space.apply(restitution, a_restitution);
  const double compressed = kineticEnergy(bodies, v);
  const double returned = restitution.dot(a_restitution);
  const double cross = restitution.dot(space.normalVelocities(v));
  const double allowed = before + owed - compressed;
  double scale = 1.0;
  if (cross + 0.5 * returned > allowed && returned > 0) {
    scale = std::clamp(
        (-cross + std::sqrt(std::max(0.0, cross * cross + 2 * returned * allowed))) / returned, 0.0,
        1.0);
  }
  return scale;
}

/// What the sub-step's solves and sweeps may still iterate (SteppedSettings::max_total_iterations)
/// after those of `outcome` so far.
int totalLeft(const SteppedSettings& settings, const SteppedOutcome& outcome) {
  return std::max(0, settings.max_total_iterations - outcome.iterations - outcome.friction_sweeps);
}

/// A solve's iterations at most: its own bound, and what the sub-step has left after `outcome`'s
/// and `pending` more not yet added to it.
int solveIterations(const SteppedSettings& settings, const SteppedOutcome& outcome, int pending) {
  return std::max(0, std::min(settings.max_iterations, totalLeft(settings, outcome) - pending));
}

/// Stage 1, the bounce (header): the touching contacts compressed jointly (d' >= 0), then the
/// struck ones leave at their bounce speed and the others do not approach (d' >= e u where
/// struck, else >= 0), the restitution scaled down where it would add kinetic energy.
void bounce(const std::vector<SteppedBody>& bodies, const std::vector<SteppedContact>& contacts,
            const SteppedSettings& settings, double tolerance, const Strikes& strikes,
            SteppedOutcome& outcome) {
  std::vector<Eigen::Vector3d>& v = outcome.velocity;
  const std::vector<std::size_t> order = contactOrder(contacts, strikes.touching);
  const ContactSpace space(bodies, contacts, order);
  const double infinity = std::numeric_limits<double>::infinity();
  const double before = kineticEnergy(bodies, v);
  const BoundedSolution compression =
      solveBounded(space, space.normalVelocities(v), Eigen::VectorXd::Zero(space.size()), tolerance,
                   solveIterations(settings, outcome, 0), infinity);
  space.addVelocityChanges(compression.impulses, v);
  Eigen::VectorXd q = space.normalVelocities(v);
  for (Eigen::Index i = 0; i < space.size(); ++i) {
    q[i] -= strikes.bounce_speed[order[static_cast<std::size_t>(i)]];
  }
  const BoundedSolution restitution =
      solveBounded(space, q, Eigen::VectorXd::Zero(space.size()), tolerance,
                   solveIterations(settings, outcome, compression.iterations), infinity);
  outcome.iterations += compression.iterations + restitution.iterations;
  outcome.converged = outcome.converged && compression.converged && restitution.converged;
  const double scale =
      restitutionScale(bodies, space, restitution.impulses, v, before, strikes.owed);
  space.addVelocityChanges(scale * restitution.impulses, v);
  for (Eigen::Index i = 0; i < space.size(); ++i) {
    outcome.contacts[order[static_cast<std::size_t>(i)]].bounce_impulse =
        compression.impulses[i] + scale * restitution.impulses[i];
  }
}

/// Stage 2, gravity (header): every movable body's velocity gains its kick.
void addGravity(const std::vector<SteppedBody>& bodies, std::vector<Eigen::Vector3d>& v) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass > 0) v[i] += bodies[i].kick;
  }
}

/// Stage 3, gap keeping (header), from the `warm` impulses (per contact; empty for none). A
/// contact not `touching` at the start that the keeping stops arrives in the sub-step: the speed
/// it was closing at is recorded (its bounce is the next sub-step's).
BoundedSolution keepGapsFrom(const std::vector<SteppedBody>& bodies,
                             const std::vector<SteppedContact>& contacts,
                             const std::vector<std::size_t>& order, const std::vector<double>& warm,
                             const SteppedSettings& settings, double tolerance,
                             const std::vector<char>& touching, SteppedOutcome& outcome) {
  std::vector<Eigen::Vector3d>& v = outcome.velocity;
  Eigen::VectorXd start = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(order.size()));
  if (warm.size() == contacts.size()) {
    for (std::size_t i = 0; i < order.size(); ++i) {
      start[static_cast<Eigen::Index>(i)] = warm[order[i]];
    }
  }
  std::vector<double> closing_before(contacts.size());  // before the gaps are kept
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    closing_before[k] = contacts[k].normal.dot(v[contacts[k].a] - v[contacts[k].b]);
  }
  BoundedSolution kept = keepGaps(bodies, contacts, order, start, settings.duration, tolerance,
                                  settings.max_iterations, totalLeft(settings, outcome), v);
  outcome.iterations += kept.iterations;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::size_t k = order[i];
    if (!touching[k] && kept.impulses[static_cast<Eigen::Index>(i)] > 0 && closing_before[k] > 0) {
      outcome.contacts[k].arrival_speed = closing_before[k];
    }
  }
  return kept;
}

/// The contacts that carry a normal impulse (`keeping`: the gap keeping's, in the solve's
/// order) and have friction, as the friction step takes them: in the solve's order, each with
/// its bound mu J and its warm start.
struct PressedContacts {
  std::vector<ClusterContact> contacts;
  std::vector<SweptFrictionContact> frictions;
  std::vector<std::size_t> index;  ///< each one's contact
};

PressedContacts pressedContacts(const std::vector<SteppedContact>& contacts,
                                const std::vector<std::size_t>& order,
                                const Eigen::VectorXd& keeping, const SteppedOutcome& outcome) {
  PressedContacts pressed;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::size_t k = order[i];
    const double normal =
        outcome.contacts[k].bounce_impulse + keeping[static_cast<Eigen::Index>(i)];
    if (!(normal > 0) || !(contacts[k].friction > 0)) continue;
    const SteppedContact& c = contacts[k];
    pressed.contacts.push_back(ClusterContact{c, 0.0});
    pressed.frictions.push_back(SweptFrictionContact{c.friction * normal, c.friction_warm});
    pressed.index.push_back(k);
  }
  return pressed;
}

/// Stage 4, friction (header): Coulomb's impulses on the pressed contacts, then the gaps kept
/// again, whose impulses (and convergence) `kept` takes on.
void frictionThenGaps(const std::vector<SteppedBody>& bodies,
                      const std::vector<SteppedContact>& contacts,
                      const std::vector<std::size_t>& order, const SteppedSettings& settings,
                      double tolerance, BoundedSolution& kept, SteppedOutcome& outcome) {
  std::vector<Eigen::Vector3d>& v = outcome.velocity;
  std::vector<Eigen::Vector3d>& w = outcome.angular_velocity;
  std::vector<ClusterBody> cluster_bodies(bodies.begin(), bodies.end());  // without the kick
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    cluster_bodies[i].velocity = v[i];
    cluster_bodies[i].angular_velocity = w[i];
  }
  const PressedContacts pressed = pressedContacts(contacts, order, kept.impulses, outcome);
  if (pressed.contacts.empty()) return;
  std::vector<SweptFrictionOutcome> friction_outcomes;
  const SweptFrictionReport swept = settings.friction(
      cluster_bodies, pressed.contacts, pressed.frictions, tolerance,
      std::min(settings.max_friction_sweeps, totalLeft(settings, outcome)), friction_outcomes);
  outcome.friction_sweeps += swept.sweeps;
  outcome.friction_converged = outcome.friction_converged && swept.converged;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    v[i] = cluster_bodies[i].velocity;
    w[i] = cluster_bodies[i].angular_velocity;
  }
  for (std::size_t j = 0; j < pressed.index.size(); ++j) {
    SteppedContactOutcome& received = outcome.contacts[pressed.index[j]];
    const Eigen::Vector3d& impulse = friction_outcomes[j].impulse;
    received.friction_impulse = impulse.norm();
    received.friction_direction = received.friction_impulse > 0
                                      ? Eigen::Vector3d(impulse / received.friction_impulse)
                                      : Eigen::Vector3d::Zero();
    received.sticking = friction_outcomes[j].sticking;
  }
  const BoundedSolution again = keepGaps(
      bodies, contacts, order, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(order.size())),
      settings.duration, tolerance, settings.max_iterations, totalLeft(settings, outcome), v);
  outcome.iterations += again.iterations;
  kept.impulses += again.impulses;
  kept.converged = again.converged;
}

/// A solve fell short: the sub-step ends before any contact closes past its band (for an
/// overlap: before it deepens past it), at the first instant one would; where that leaves too
/// short a sub-step, every movable body is held still over it instead.
void endEarlyOrHold(const std::vector<SteppedBody>& bodies,
                    const std::vector<SteppedContact>& contacts, double h,
                    SteppedOutcome& outcome) {
  std::vector<Eigen::Vector3d>& v = outcome.velocity;
  std::vector<Eigen::Vector3d>& w = outcome.angular_velocity;
  double duration = h;
  for (const SteppedContact& c : contacts) {
    const double closing = c.normal.dot(v[c.a] - v[c.b]);  // -d'
    const double room = std::max(c.gap, 0.0);
    if (closing > 0 && room - closing * h < -0.5 * c.band) {
      duration = std::min(duration, room / closing);
    }
  }
  if (duration >= kShortestSubstep * h) {
    outcome.duration = duration;
    return;
  }
  outcome.held = true;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass > 0) {
      v[i].setZero();
      w[i].setZero();
    }
  }
  for (SteppedContactOutcome& out : outcome.contacts) {
    out.keeping_impulse = 0.0;
    out.friction_impulse = 0.0;
  }
}

}  // namespace

SteppedOutcome solveSteppedSubstep(const std::vector<SteppedBody>& bodies,
                                   const std::vector<SteppedContact>& contacts,
                                   const SteppedSettings& settings,
                                   const std::vector<double>& warm) {
  SteppedOutcome outcome = startingOutcome(bodies, contacts.size(), settings.duration);
  const double tolerance = solveTolerance(contacts, settings.duration);
  const Strikes strikes = findStrikes(bodies, contacts, settings, outcome);
  if (strikes.any) bounce(bodies, contacts, settings, tolerance, strikes, outcome);
  addGravity(bodies, outcome.velocity);
  const std::vector<std::size_t> order =
      contactOrder(contacts, std::vector<char>(contacts.size(), 1));
  BoundedSolution kept =
      keepGapsFrom(bodies, contacts, order, warm, settings, tolerance, strikes.touching, outcome);
  if (settings.friction && !contacts.empty()) {
    frictionThenGaps(bodies, contacts, order, settings, tolerance, kept, outcome);
  }
  outcome.converged = outcome.converged && kept.converged;
  for (std::size_t i = 0; i < order.size(); ++i) {
    outcome.contacts[order[i]].keeping_impulse = kept.impulses[static_cast<Eigen::Index>(i)];
  }
  if (!outcome.converged) endEarlyOrHold(bodies, contacts, settings.duration, outcome);
  return outcome;
}

}  // namespace collision_response::core
