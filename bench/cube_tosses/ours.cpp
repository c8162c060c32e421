// Our model on the real cube tosses (issue 42, step 8; scripts/cube_tosses.sh writes
// doc/cube_tosses.md from what this prints beside the peers' run, main.cpp). The core alone
// (predictImpacts, include/collision_response/core/prediction.h), as far as it goes today: a
// shaped body's prediction flies the cube exactly, finds its first contacts with the table
// certified and resolves its impacts with rotation, and ENDS where its contact would last
// (resting, sliding, rocking: not modelled yet, doc/model.md "Prediction of a shaped body"). So
// each toss is measured over the span the prediction covers, the samples up to where it ends.
// 1. the tosses split as the peers' (tosses.h): every 4th by file name fits, the others evaluate;
// 2. e and mu fitted on the fitting tosses by the peers' grid and objective (each toss's mean
//    centre error in widths, averaged over the tosses), each toss's mean taken over its span,
//    and each grid point's median span written beside its objective: the span depends on e and
//    mu, and the objective is least where the span is shortest (at e = 0 the cube's contact lasts
//    from its first touch), so this fit is degenerate, and the report says so;
// 3. each evaluation toss predicted from its first recorded state at the fitted e and mu, horizon
//    its recorded duration, sampled every 1/148 s; per toss the span covered (samples, s, why it
//    ended), the centre's distance (widths) and the orientation's angle (deg) at every sample of
//    the span, its impacts, the CPU;
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
  bool lasting = false;                ///< it ended at a lasting contact (cut short)
  std::string message;                 ///< the prediction's, as it is
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

/// A grid point of the fit: the objective, the peers' over our span (the mean over the tosses
/// predicted of each toss's mean centre error over its span, widths), the median over them of
/// the fraction of its samples the span covers, and the tosses refused (not predicted).
struct GridPoint {
  Contact contact;
  double objective = std::numeric_limits<double>::infinity();
  double median_covered = 0.0;
  std::size_t refused = 0;
};

GridPoint gridPoint(const Contact& contact, const std::vector<const Toss*>& tosses) {
  const core::Scene scene = cubeScene(contact);
  GridPoint point{contact, 0.0, 0.0, 0};
  std::vector<double> covered;
  for (const Toss* toss : tosses) {
    const Played played = play(scene, *toss);
    if (played.refused) {
      ++point.refused;
      continue;
    }
    point.objective += played.mean_distance;
    covered.push_back(static_cast<double>(played.covered) /
                      static_cast<double>(toss->samples.size()));
  }
  if (covered.empty()) {
    point.objective = std::numeric_limits<double>::infinity();
    return point;
  }
  point.objective /= static_cast<double>(covered.size());
  std::sort(covered.begin(), covered.end());
  const std::size_t half = covered.size() / 2;
  point.median_covered =
      covered.size() % 2 ? covered[half] : 0.5 * (covered[half - 1] + covered[half]);
  return point;
}

/// The reason a prediction ended, in a few words, for the counts: the horizon, a lasting
/// contact, or the rest of its message.
std::string endReason(const Played& played) {
  if (played.refused) return "refused: " + *played.refused;
  if (!played.lasting) return "the horizon (the toss's recorded end)";
  if (played.message.find("lasting contact") != std::string::npos) {
    return "a lasting contact with the table (not yet modelled)";
  }
  return "cut short: " + played.message;
}

/// One toss, every sample of its span printed: a reproducer.
int printToss(const Contact& contact, const std::vector<Toss>& tosses, const std::string& name) {
  const auto toss =
      std::find_if(tosses.begin(), tosses.end(), [&](const Toss& t) { return t.name == name; });
  if (toss == tosses.end()) throw std::runtime_error("no toss named " + name);
  const Played played = play(cubeScene(contact), *toss);
  std::cout << toss->name << " at e " << contact.restitution << ", mu " << contact.friction << ": "
            << endReason(played) << "\n";
  if (played.refused) return 1;
  std::cout << "ends at +" << played.end_time << " s, " << played.covered << " of "
            << toss->samples.size() << " samples, " << played.impacts
            << " impacts; message: " << played.message << "\nlowest corner over the table (least) "
            << played.deepest << " m; energy gained (most) " << played.energy_gained << " J of "
            << played.first_energy << " J\nk  distance (widths)  angle (deg)\n";
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
    ends[endReason(played[i])].push_back(evaluation[i]->name);
    if (played[i].breach) breaches.push_back(evaluation[i]->name);
  }
  std::cerr << "== ours, " << label << ": e " << contact.restitution << ", mu " << contact.friction
            << "\n";
  for (const auto& [reason, names] : ends) {
    std::cerr << "   ended by " << reason << ": " << names.size() << " tosses\n";
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
        << ", \"lasting\": " << (p.lasting ? "true" : "false") << ", \"impacts\": " << p.impacts
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
  std::string grid_json = "[]";  // e, mu, objective, median fraction covered, refused
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
                    << " of the samples (median)\n";
        });
    std::cerr << "   e " << fitted.best.restitution << ", mu " << fitted.best.friction
              << ", mean error over the span " << fitted.objective << " widths ("
              << fitted.evaluations << " grid points, " << fitted.cpu << " s CPU; at most "
              << fit_refused << " fitting tosses refused at a point)\n";
    grid_json = "[";
    for (std::size_t i = 0; i < grid.size(); ++i) {
      grid_json += std::string(i ? ",\n  " : "") + "[" + json(grid[i].contact.restitution) + ", " +
                   json(grid[i].contact.friction) + ", " + json(grid[i].objective) + ", " +
                   json(grid[i].median_covered) + ", " + std::to_string(grid[i].refused) + "]";
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
