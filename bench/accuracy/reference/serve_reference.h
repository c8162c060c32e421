// The served ball's reference (serve_reference.py beside this file, 40-digit mpmath), as the
// benchmark and the tests read it: each line of serve_reference.txt a name and its numbers ('#'
// lines are comments). Eigen only.
#pragma once

#include <Eigen/Core>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace collision_response::bench {

class ServeReference {
 public:
  /// Throws where the file cannot be read.
  static ServeReference read(const std::string& path) {
    std::ifstream file(path);
    if (!file) throw std::runtime_error("cannot read the serve's reference " + path);
    ServeReference reference;
    std::string line;
    while (std::getline(file, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      std::string name;
      fields >> name;
      for (double x; fields >> x;) reference.values_[name].push_back(x);
    }
    return reference;
  }
  /// A number, or a vector of three; throws where the file has no such line.
  double value(const std::string& name) const { return at(name, 1)[0]; }
  Eigen::Vector3d vector(const std::string& name) const {
    const std::vector<double>& x = at(name, 3);
    return Eigen::Vector3d(x[0], x[1], x[2]);
  }

 private:
  const std::vector<double>& at(const std::string& name, std::size_t size) const {
    const auto found = values_.find(name);
    if (found == values_.end() || found->second.size() != size) {
      throw std::runtime_error("the serve's reference has no " + name + " of " +
                               std::to_string(size) + " numbers");
    }
    return found->second;
  }
  std::map<std::string, std::vector<double>> values_;
};

}  // namespace collision_response::bench
