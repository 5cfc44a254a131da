#include "json_input.hpp"

#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"

namespace fovea::core::detail {

std::string json_error_text(const nlohmann::json::exception& e) {
  const std::string_view w = e.what();
  const auto close = w.find("] ");
  return std::string(w.starts_with("[json.exception.") && close != w.npos ? w.substr(close + 2) : w);
}

nlohmann::json parse_json_input(std::string_view text, std::string_view origin) {
  check_json_nesting(text, origin, kMaxJsonDepth);
  std::string key;  // the last object key read: where a bad value sits
  const auto track = [&key](int, nlohmann::json::parse_event_t ev, nlohmann::json& parsed) {
    if (ev == nlohmann::json::parse_event_t::key && parsed.is_string()) key = parsed.get<std::string>();
    return true;
  };
  try {
    return nlohmann::json::parse(text, track);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string(origin) + ": invalid JSON" + (key.empty() ? "" : " at \"" + key + "\"") + ": " +
                     json_error_text(e));
  }
}

}  // namespace fovea::core::detail
