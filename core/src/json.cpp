#include "fovea/core/json.hpp"

namespace fovea::core {

nlohmann::json parse_json(std::string_view text) { return nlohmann::json::parse(text); }

nlohmann::json parse_json(std::istream& in) { return nlohmann::json::parse(in); }

nlohmann::json parse_json_or_discarded(std::istream& in) { return nlohmann::json::parse(in, nullptr, false); }

}  // namespace fovea::core
