#pragma once
// Parsing of gaze-source URIs ("scheme:body?key=value&...") shared by the factories.
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

struct SourceUri {
  std::string text, scheme, body;
  std::map<std::string, std::string> query;
  std::string take(const std::string& key);  // "" if absent; removes the key
  double take_number(const std::string& key, double fallback, double lo, double hi);
  // seconds=S of the generated sources: a length in (0, 1e6] s, `fallback` when absent. An
  // explicit 0 is refused: it read as "endless", and a tool walking every sample never ended.
  double take_seconds(double fallback);
  void finish() const;  // throws for any key nobody took
  std::string rebuilt() const;  // "scheme:body?k=v&..." with the keys not yet taken
};

SourceUri parse_source_uri(std::string_view uri);
// speed=S (0.001..1000) and loop=0|1 of recordings, checked wherever one is opened.
void take_timeline_keys(SourceUri& u, SourceOptions& opt);
// hid:, usb:, hid-capture:, mouse, openxr (devices' own translation units).
std::unique_ptr<SampleStream> open_device_stream(SourceUri& u, const SourceOptions& opt);
// tracker=PRESET and the tracker_* keys (tracker_model.cpp); false when none is given.
struct TrackerParams;
bool take_tracker_options(SourceUri& u, TrackerParams& p);

}  // namespace fovea::devices
