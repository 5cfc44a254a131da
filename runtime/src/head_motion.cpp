#include "head_motion.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <glm/gtc/constants.hpp>

#include "fovea/core/error.hpp"

namespace fovea::runtime {

HeadMotion HeadMotion::scripted() {
  HeadMotion h;
  h.kind_ = Kind::Scripted;
  return h;
}

HeadMotion HeadMotion::stationary() { return HeadMotion{}; }

HeadMotion HeadMotion::from_spec(const std::string& spec) {
  if (spec.empty() || spec == "scripted") return scripted();
  if (spec == "static") return stationary();
  return from_file(spec);
}

HeadMotion HeadMotion::from_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError(path + ": cannot open head pose file");
  HeadMotion h;
  h.kind_ = Kind::Samples;
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream ss(line);
    std::vector<std::string> tokens;
    for (std::string tok; ss >> tok;) tokens.push_back(tok);
    if (tokens.empty()) continue;  // blank or comment line
    const std::string where = path + ":" + std::to_string(lineno);
    if (tokens.size() != 8) throw core::InputError(where + ": expected \"t px py pz qx qy qz qw\"");
    double v[8];
    for (int i = 0; i < 8; ++i) {
      char* end = nullptr;
      v[i] = std::strtod(tokens[size_t(i)].c_str(), &end);
      if (*end != '\0' || !std::isfinite(v[i]))
        throw core::InputError(where + ": \"" + tokens[size_t(i)] + "\" is not a finite number");
    }
    const glm::dquat q(v[7], v[4], v[5], v[6]);
    const double len = glm::length(q);
    if (std::abs(len - 1.0) > 1e-3) throw core::InputError(where + ": quaternion is not unit length");
    if (!h.samples_.empty() && v[0] <= h.samples_.back().t)
      throw core::InputError(where + ": time must increase strictly");
    h.samples_.push_back({v[0], core::Pose{q / len, {v[1], v[2], v[3]}}});
  }
  if (h.samples_.empty()) throw core::InputError(path + ": no head pose samples");
  return h;
}

core::Pose HeadMotion::at(core::TimeNs since_epoch) const {
  const double t = core::ns_to_ms(since_epoch) * 1e-3;
  switch (kind_) {
    case Kind::Static: return {};
    case Kind::Scripted: {
      const double two_pi = glm::two_pi<double>();
      const double yaw = glm::radians(10.0) * std::sin(two_pi * t / 8.0);
      const double pitch = glm::radians(5.0) * std::sin(two_pi * t / 11.0);
      core::Pose p;
      p.orientation = glm::angleAxis(yaw, glm::dvec3(0, 1, 0)) * glm::angleAxis(pitch, glm::dvec3(1, 0, 0));
      p.position = {0.02 * std::sin(two_pi * t / 6.0), 0.01 * std::sin(two_pi * t / 5.0), 0.0};
      return p;
    }
    case Kind::Samples: {
      if (t <= samples_.front().t) return samples_.front().pose;
      if (t >= samples_.back().t) return samples_.back().pose;
      size_t i = 1;
      while (samples_[i].t < t) ++i;
      const Sample& a = samples_[i - 1];
      const Sample& b = samples_[i];
      const double u = (t - a.t) / (b.t - a.t);
      return {glm::slerp(a.pose.orientation, b.pose.orientation, u), glm::mix(a.pose.position, b.pose.position, u)};
    }
  }
  return {};
}

}  // namespace fovea::runtime
