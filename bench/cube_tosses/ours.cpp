// Our model on the real cube tosses (issue 42, step 8; scripts/cube_tosses.sh writes
// doc/cube_tosses.md from what this prints beside the peers' run, main.cpp). The core alone
// (predictImpacts, include/collision_response/core/prediction.h), as far as it goes today: a
// shaped body's prediction flies the cube exactly, finds its contacts with the table certified,
// resolves its impacts with rotation, and where the contact lasts on the table's face goes on by
// that contact's closed forms (resting, sliding, rolling: doc/model.md "Prediction of a shaped
// body"); a lasting contact those forms do not carry yet (tipping over an edge or a corner,
// rocking, spin about the face's normal while sliding or resting, ...) ENDS the prediction there,
// its message naming it. So each toss is measured over the span the prediction covers, the
// samples up to where it ends; where it reaches the recording's end (the horizon) resting on the
// table, the last sample is the error at rest, as the peers' (main.cpp); one reaching the end
// still bouncing (in flight) or sliding is counted so, not at rest.
// 1. the tosses split as the peers' (tosses.h): every 4th by file name fits, the others evaluate;
// 2. e and mu fitted on the fitting tosses by the peers' grid and objective (each toss's mean
//    centre error in widths, averaged over the tosses), each toss's mean taken over its span,
//    and each grid point's median span and shares of tosses reaching the end, and at rest there,
//    written beside its
//    objective: where the span depends on e and mu, the objective is least where the span is
//    shortest, and the fit is degenerate (the report says whether it is);
// 3. each evaluation toss predicted from its first recorded state at the fitted e and mu, horizon
//    its recorded duration, sampled every 1/148 s; per toss the span covered (samples, s, why it
//    ended: reasonOf, the contact's state where it reached the end), the centre's distance
//    (widths) and the orientation's angle (deg) at every sample of the span, its impacts, the CPU;
// 4. every sample checked against what the model promises: no point of the cube below the table
//    (by more than 1e-9 m) and no energy gained (kinetic, rotational and potential above the
//    first state's by more than 1e-9 of it): any breach is counted and its toss named.
// 5. the evaluation again at each pair given by --at (the report gives each peer's fitted pair):
//    our model and that peer at the same e and mu, over our span.
//   cube_tosses_ours [--tosses DIR] [--out FILE.json] [--contact E MU] [--at LABEL E MU]...
//                    [--toss NAME]
// --contact: no fit, the evaluation at E and MU; --toss: that toss alone at --contact's E and
// MU, every sample printed (a reproducer). The tosses are read as main.cpp reads them (DIR,
// else COLLISION_RESPONSE_CUBE_TOSSES, else beside the project's root; missing: exit 77).
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <map>
#include <optional>
#include <regex>

#include "collision_response/core/prediction.h"
#include "cube_tosses.h"
#include "tosses.h"

namespace collision_response::bench::cube_tosses {
namespace {

/// No point of the cube below the table by more than this (m), no energy gained by more than
/// this fraction of the first state's (the bounds test/core/test_shaped_prediction.cpp holds
/// tumbling throws to).
constexpr double kInsideTolerance = 1e-9;
constexpr double kEnergyTolerance = 1e-9;

/// The cube over the table: the uniform solid box (its inertia m w^2 / 6 about any axis, the
/// shape's default), the table's top the plane z = kTableTop, gravity and friction, e and mu the
/// pair's.
core::Scene cubeScene(const Contact& contact) {
  core::Scene scene;
  scene.effects.gravity = true;
  scene.effects.friction = true;
  scene.gravity = V(0, 0, -kGravity);
  const auto check = [](const core::Status& status) {
    if (!status) throw std::runtime_error(status.error().message());
  };
  check(scene.materials.addMaterial("acrylic", core::Material{contact.restitution, {}}, "cube"));
  check(scene.materials.addMaterial("table", core::Material{contact.restitution, {}}, "table"));
  check(scene.materials.addPair(
      "acrylic", "table", core::PairCoefficients{contact.restitution, contact.friction}, "pair"));
  core::BodySpec cube;
  cube.id = "cube";
  cube.mass = kMass;
  cube.material = "acrylic";
  cube.shape = core::BodyShape::kBox;
  cube.size = V::Constant(kWidth);
  scene.bodies = {cube};
  core::ObstacleSpec table;
  table.id = "table";
  table.normal = V::UnitZ();
  table.offset = kTableTop;
  table.material = "table";
  scene.obstacles = {table};
  return scene;
}

/// The height of the cube's lowest corner above the table (m): each body axis turned down by
/// the half width.
double lowestCorner(const core::BodyStateSample& state) {
  const Eigen::Matrix3d rotation = state.orientation.normalized().toRotationMatrix();
  return state.position.z() - kHalfWidth * rotation.row(2).cwiseAbs().sum() - kTableTop;
}

/// Kinetic, rotational (isotropic: kInertia |w|^2 / 2) and potential energy over the table, J.
double energy(const core::BodyStateSample& state) {
  return 0.5 * kMass * state.velocity.squaredNorm() +
         0.5 * kInertia * state.angular_velocity.squaredNorm() +
         kMass * kGravity * (state.position.z() - kTableTop);
}

/// One toss predicted, against its recording over the span the prediction covers.
struct Played {
  std::optional<std::string> refused;  ///< the error's field and message: not predicted
  std::size_t covered = 0;             ///< samples of the span, the first one included
  double end_time = 0.0;               ///< s: where the prediction ends
  bool lasting = false;                ///< it ended before the horizon (cut short)
  bool reached = false;                ///< it covers every sample: the recording's end
  bool rested = false;                 ///< reached, every contact there resting: at rest
  /// The contact's state at the end (the prediction's contacts: "resting", "sliding",
  /// "rolling", several joined by "+"), or "in flight" without any.
  std::string end_motion;
  std::string message;  ///< the prediction's, as it is
  std::size_t impacts = 0;
  std::vector<double> distance, angle;  ///< per sample of the span (widths, deg)
  double mean_distance = 0.0, end_distance = 0.0, mean_angle = 0.0, end_angle = 0.0;
  double deepest = std::numeric_limits<double>::infinity();         ///< m: the least lowest corner
  double energy_gained = -std::numeric_limits<double>::infinity();  ///< J, the most over E0
  double first_energy = 0.0;                                        ///< J
  bool breach = false;  ///< inside the table or energy gained, past the tolerances
};

Played play(const core::Scene& scene, const Toss& toss) {
  const State first = firstState(toss);
  core::PredictionRequest request;
  request.body = scene.bodies.front();
  request.state.position = first.pose.position;
  request.state.orientation = first.pose.orientation;
  request.state.velocity = first.velocity;
  request.state.angular_velocity = first.angular_velocity;  // world frame
  const std::size_t n = toss.samples.size();
  request.horizon = static_cast<double>(n - 1) / kSampleRate;
  request.max_impacts = core::kPredictionMaxImpacts;
  request.effects = scene.effects;
  request.sample_period = 1.0 / kSampleRate;
  Played played;
  const auto prediction = core::predictImpacts(scene, nullptr, core::MonitorSettings{}, request);
  if (!prediction) {
    played.refused = prediction.error().message();
    return played;
  }
  played.end_time = prediction->final_state.time;
  played.lasting = prediction->cut_short;
  played.message = prediction->message;
  played.impacts = prediction->impacts.size();
  std::vector<std::string> motions;
  for (const core::ContactRecord& contact : prediction->contacts) {
    const std::string motion = core::toString(contact.state);
    if (std::find(motions.begin(), motions.end(), motion) == motions.end()) {
      motions.push_back(motion);
    }
  }
  for (const std::string& motion : motions) {
    played.end_motion += (played.end_motion.empty() ? "" : "+") + motion;
  }
  if (played.end_motion.empty()) played.end_motion = "in flight";
  played.first_energy = energy(request.state);
  for (std::size_t k = 0; k < prediction->samples.size() && k < n; ++k) {
    const core::BodyStateSample& sample = prediction->samples[k];
    // The k-th sample is at k / 148 s, as the recording's k-th row.
    if (std::abs(sample.time * kSampleRate - static_cast<double>(k)) > 1e-6) {
      throw std::runtime_error(toss.name + ": sample " + std::to_string(k) + " is at " +
                               std::to_string(sample.time) + " s, not at k / 148 s");
    }
    const Pose& recorded = toss.samples[k].pose;
    played.distance.push_back((sample.position - recorded.position).norm() / kWidth);
    played.angle.push_back(angleBetween(sample.orientation.normalized(), recorded.orientation));
    played.deepest = std::min(played.deepest, lowestCorner(sample));
    played.energy_gained = std::max(played.energy_gained, energy(sample) - played.first_energy);
  }
  played.covered = played.distance.size();
  if (played.covered == 0) throw std::runtime_error(toss.name + ": no sample predicted");
  played.reached = !played.lasting && played.covered == n;
  played.rested = played.reached && played.end_motion == "resting";
  for (std::size_t k = 0; k < played.covered; ++k) {
    played.mean_distance += played.distance[k] / static_cast<double>(played.covered);
    played.mean_angle += played.angle[k] / static_cast<double>(played.covered);
  }
  played.end_distance = played.distance.back();
  played.end_angle = played.angle.back();
  played.breach = played.deepest < -kInsideTolerance ||
                  played.energy_gained > kEnergyTolerance * played.first_energy;
  return played;
}

/// The median of `values` (the mean of the middle two of an even count; NaN if empty).
double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const std::size_t half = values.size() / 2;
  return values.size() % 2 ? values[half] : 0.5 * (values[half - 1] + values[half]);
}

/// A grid point of the fit: the objective, the peers' over our span (the mean over the tosses
/// predicted of each toss's mean centre error over its span, widths), the median over them of
/// the fraction of its samples the span covers, the fraction of them whose prediction reaches
/// the recording's end, and the tosses refused (not predicted).
struct GridPoint {
  Contact contact;
  double objective = std::numeric_limits<double>::infinity();
  double median_covered = 0.0;
  double reached = 0.0;
  double rested = 0.0;
  std::size_t refused = 0;
};

GridPoint gridPoint(const Contact& contact, const std::vector<const Toss*>& tosses) {
  const core::Scene scene = cubeScene(contact);
  GridPoint point{contact, 0.0, 0.0, 0.0, 0.0, 0};
  std::vector<double> covered;
  for (const Toss* toss : tosses) {
    const Played played = play(scene, *toss);
    if (played.refused) {
      ++point.refused;
      continue;
    }
    point.objective += played.mean_distance;
    if (played.reached) point.reached += 1.0;
    if (played.rested) point.rested += 1.0;
    covered.push_back(static_cast<double>(played.covered) /
                      static_cast<double>(toss->samples.size()));
  }
  if (covered.empty()) {
    point.objective = std::numeric_limits<double>::infinity();
    return point;
  }
  point.objective /= static_cast<double>(covered.size());
  point.reached /= static_cast<double>(covered.size());
  point.rested /= static_cast<double>(covered.size());
  point.median_covered = median(covered);
  return point;
}

/// The reason a prediction ended, in a few words, for the counts: the recording's end (and the
/// contact's state there), or what ended it before. A lasting contact not modelled yet is named
/// by the words of its refusal (shaped_prediction.cpp's "... which is not yet modelled (WHY), and
/// the prediction ends there", WHY "field: not yet: what: details"): `what`, its numbers left out.
std::string reasonOf(const Played& played) {
  if (played.refused) return "refused: " + *played.refused;
  if (played.reached) return "reaches the recording's end, " + played.end_motion;
  if (!played.lasting) return "ends before the recording's end uncut (the samples stop)";
  const std::string& message = played.message;
  const std::string opening = "which is not yet modelled (";
  const std::string closing = "), and the prediction ends there";
  const auto from = message.find(opening);
  const auto to = message.rfind(closing);
  if (from != std::string::npos && to != std::string::npos && to > from) {
    std::string why = message.substr(from + opening.size(), to - from - opening.size());
    // The field ("contact: ", "body.velocity: ") and "not yet: " left out.
    if (const auto field = why.find(": ");
        field != std::string::npos && why.substr(0, field).find(' ') == std::string::npos) {
      why = why.substr(field + 2);
    }
    if (why.rfind("not yet: ", 0) == 0) why = why.substr(9);
    if (const auto detail = why.find(':'); detail != std::string::npos) why.resize(detail);
    why = std::regex_replace(why, std::regex(" at [-+0-9.e]+ m/s"), "");
    return "not modelled: " + why;
  }
  if (const auto ends = message.find("' ends at +"); ends != std::string::npos) {
    // "the body's lasting contact with 'table' ends at +T s (WHY), which is not yet modelled"
    const auto open = message.find('(', ends);
    const auto close = message.find(')', open);
    if (open != std::string::npos && close != std::string::npos) {
      return "its lasting motion ends: " + message.substr(open + 1, close - open - 1);
    }
  }
  return "cut short: " + message;
}

/// One toss, every sample of its span printed: a reproducer.
int printToss(const Contact& contact, const std::vector<Toss>& tosses, const std::string& name) {
  const auto toss =
      std::find_if(tosses.begin(), tosses.end(), [&](const Toss& t) { return t.name == name; });
  if (toss == tosses.end()) throw std::runtime_error("no toss named " + name);
  const Played played = play(cubeScene(contact), *toss);
  std::cout << toss->name << " at e " << contact.restitution << ", mu " << contact.friction << ": "
            << reasonOf(played) << "\n";
  if (played.refused) return 1;
  std::cout << "ends at +" << played.end_time << " s, " << played.covered << " of "
            << toss->samples.size() << " samples, " << played.impacts
            << " impacts; message: " << played.message << "\nlowest corner over the table (least) "
            << played.deepest << " m; energy gained (most) " << played.energy_gained << " J of "
            << played.first_energy << " J; at the end: " << played.end_motion
            << "\nk  distance (widths)  angle (deg)\n";
  for (std::size_t k = 0; k < played.covered; ++k) {
    std::cout << k << "  " << played.distance[k] << "  " << played.angle[k] << "\n";
  }
  return played.breach ? 3 : 0;
}

/// The evaluation tosses predicted at one pair, as JSON: how each ended, grouped by reason;
/// the breaches named; per toss its span, impacts, CPU and errors at every sample of the span.
std::string evaluate(const std::string& label, const Contact& contact, const Fit* fitted,
                     const std::vector<const Toss*>& evaluation) {
  const core::Scene scene = cubeScene(contact);
  std::vector<Played> played;
  std::vector<double> cpu;
  for (const Toss* toss : evaluation) {
    const double started = cpuSeconds();
    played.push_back(play(scene, *toss));
    cpu.push_back(cpuSeconds() - started);
  }
  std::map<std::string, std::vector<std::string>> ends;  // reason -> tosses
  std::vector<std::string> breaches;
  for (std::size_t i = 0; i < played.size(); ++i) {
    ends[reasonOf(played[i])].push_back(evaluation[i]->name);
    if (played[i].breach) breaches.push_back(evaluation[i]->name);
  }
  std::cerr << "== ours, " << label << ": e " << contact.restitution << ", mu " << contact.friction
            << "\n";
  for (const auto& [reason, names] : ends) {
    std::cerr << "   ended by " << reason << ": " << names.size() << " tosses\n";
  }
  std::vector<double> rest_distance, rest_angle;
  for (const Played& p : played) {
    if (!p.rested) continue;
    rest_distance.push_back(p.end_distance);
    rest_angle.push_back(p.end_angle);
  }
  std::cerr << "   reaching the recording's end: "
            << std::count_if(played.begin(), played.end(),
                             [](const Played& p) { return p.reached; })
            << " of " << played.size() << " tosses; at rest there: " << rest_distance.size()
            << "\n";
  if (!rest_distance.empty()) {
    std::cerr << "   at rest: the centre " << median(rest_distance) << " widths, the angle "
              << median(rest_angle) << " deg (median)\n";
  }
  std::cerr << "   inside the table or energy gained: " << breaches.size() << " tosses";
  for (const std::string& name : breaches) std::cerr << " " << name;
  std::cerr << "\n";

  std::ostringstream out;
  out << "  {\"label\": " << jsonText(label) << ", \"restitution\": " << json(contact.restitution)
      << ", \"friction\": " << json(contact.friction);
  if (fitted) {
    out << ",\n   \"fit\": {\"mean_distance\": " << json(fitted->objective)
        << ", \"grid_points\": " << fitted->evaluations << ", \"cpu_s\": " << json(fitted->cpu)
        << "}";
  }
  out << ",\n   \"ends\": {";
  bool first = true;
  for (const auto& [reason, names] : ends) {
    out << (first ? "" : ", ") << jsonText(reason) << ": [";
    for (std::size_t i = 0; i < names.size(); ++i) out << (i ? ", " : "") << jsonText(names[i]);
    out << "]";
    first = false;
  }
  out << "},\n   \"breaches\": [";
  for (std::size_t i = 0; i < breaches.size(); ++i) {
    out << (i ? ", " : "") << jsonText(breaches[i]);
  }
  out << "],\n   \"tosses\": [\n";
  for (std::size_t i = 0; i < played.size(); ++i) {
    const Played& p = played[i];
    out << (i ? ",\n" : "") << "    {\"name\": " << jsonText(evaluation[i]->name)
        << ", \"samples\": " << evaluation[i]->samples.size()
        << ", \"refused\": " << (p.refused ? jsonText(*p.refused) : "null")
        << ", \"covered\": " << p.covered << ", \"end_s\": " << json(p.end_time)
        << ", \"lasting\": " << (p.lasting ? "true" : "false")
        << ", \"reached\": " << (p.reached ? "true" : "false")
        << ", \"rested\": " << (p.rested ? "true" : "false")
        << ", \"end_motion\": " << jsonText(p.end_motion)
        << ",\n     \"reason\": " << jsonText(reasonOf(p)) << ", \"impacts\": " << p.impacts
        << ", \"cpu_s\": " << json(cpu[i]) << ", \"deepest_m\": " << json(p.deepest)
        << ", \"energy_gained_j\": " << json(p.energy_gained)
        << ", \"first_energy_j\": " << json(p.first_energy)
        << ", \"breach\": " << (p.breach ? "true" : "false")
        << ",\n     \"message\": " << jsonText(p.message)
        << ",\n     \"distance\": " << jsonList(p.distance)
        << ",\n     \"angle\": " << jsonList(p.angle) << "}";
  }
  out << "]}";
  return out.str();
}

int run(int argc, char** argv) {
  std::filesystem::path folder = COLLISION_RESPONSE_CUBE_TOSSES;
  if (const char* given = std::getenv("COLLISION_RESPONSE_CUBE_TOSSES")) folder = given;
  std::string out_path, only;
  std::optional<Contact> given_contact;
  std::vector<std::pair<std::string, Contact>> also;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 < argc && arg == "--tosses") {
      folder = argv[++i];
    } else if (i + 1 < argc && arg == "--out") {
      out_path = argv[++i];
    } else if (i + 2 < argc && arg == "--contact") {
      given_contact = Contact{std::stod(argv[i + 1]), std::stod(argv[i + 2])};
      i += 2;
    } else if (i + 3 < argc && arg == "--at") {
      also.emplace_back(argv[i + 1], Contact{std::stod(argv[i + 2]), std::stod(argv[i + 3])});
      i += 3;
    } else if (i + 1 < argc && arg == "--toss") {
      only = argv[++i];
    } else {
      std::cerr << "usage: cube_tosses_ours [--tosses DIR] [--out FILE.json] [--contact E MU] "
                   "[--at LABEL E MU]... [--toss NAME]\n";
      return 2;
    }
  }
  if (!std::filesystem::is_directory(folder)) {
    std::cerr << "cube_tosses_ours: skipped: no cube tosses at " << folder
              << " (give --tosses DIR or set COLLISION_RESPONSE_CUBE_TOSSES)\n";
    return 77;
  }
  const std::vector<Toss> tosses = readTosses(folder);
  if (!only.empty()) {
    if (!given_contact) throw std::runtime_error("--toss needs --contact E MU");
    return printToss(*given_contact, tosses, only);
  }
  std::vector<const Toss*> fitting, evaluation;
  splitTosses(tosses, fitting, evaluation);

  std::vector<std::string> runs;
  std::size_t fit_refused = 0;
  // e, mu, objective, median fraction covered, refused, fractions reaching the end and at rest
  std::string grid_json = "[]";
  if (given_contact) {
    runs.push_back(evaluate("given", *given_contact, nullptr, evaluation));
  } else {
    std::cerr << "== ours: fitting on " << fitting.size() << " tosses, over the span predicted\n";
    std::vector<GridPoint> grid;
    const Fit fitted = fitOnGrid(
        true,
        [&](const Contact& contact) {
          grid.push_back(gridPoint(contact, fitting));
          fit_refused = std::max(fit_refused, grid.back().refused);
          return grid.back().objective;
        },
        [&](const Contact& contact, double objective) {
          std::cerr << "   e " << contact.restitution << ", mu " << contact.friction << ": "
                    << objective << " widths, the span " << grid.back().median_covered
                    << " of the samples (median), " << grid.back().reached
                    << " of the tosses to their end, " << grid.back().rested << " at rest there\n";
        });
    std::cerr << "   e " << fitted.best.restitution << ", mu " << fitted.best.friction
              << ", mean error over the span " << fitted.objective << " widths ("
              << fitted.evaluations << " grid points, " << fitted.cpu << " s CPU; at most "
              << fit_refused << " fitting tosses refused at a point)\n";
    grid_json = "[";
    for (std::size_t i = 0; i < grid.size(); ++i) {
      grid_json += std::string(i ? ",\n  " : "") + "[" + json(grid[i].contact.restitution) + ", " +
                   json(grid[i].contact.friction) + ", " + json(grid[i].objective) + ", " +
                   json(grid[i].median_covered) + ", " + std::to_string(grid[i].refused) + ", " +
                   json(grid[i].reached) + ", " + json(grid[i].rested) + "]";
    }
    grid_json += "]";
    runs.push_back(evaluate("fitted", fitted.best, &fitted, evaluation));
  }
  for (const auto& [label, contact] : also)
    runs.push_back(evaluate(label, contact, nullptr, evaluation));

  std::ostringstream out;
  out << "{\"name\": \"ours\", \"fit_refused\": " << fit_refused
      << ", \"inside_tolerance_m\": " << json(kInsideTolerance)
      << ", \"energy_tolerance\": " << json(kEnergyTolerance)
      << ",\n \"fitting\": " << jsonNames(fitting)
      << ",\n \"evaluation\": " << jsonNames(evaluation) << ",\n \"grid\": " << grid_json
      << ",\n \"runs\": [\n";
  for (std::size_t i = 0; i < runs.size(); ++i) out << (i ? ",\n" : "") << runs[i];
  out << "\n]}\n";
  writeJson(out.str(), out_path);
  return 0;
}

}  // namespace
}  // namespace collision_response::bench::cube_tosses

int main(int argc, char** argv) {
  return collision_response::bench::cube_tosses::mainOf(
      "cube_tosses_ours", collision_response::bench::cube_tosses::run, argc, argv);
}
