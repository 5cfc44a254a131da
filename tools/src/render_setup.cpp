#include "render_setup.hpp"

#include <algorithm>

namespace fovea::tools {

pipeline::FrameConfig frame_config_of(const Args& args, const std::vector<std::string>& not_frame) {
  pipeline::FrameConfig c;
  for (const std::string& name : pipeline::frame_option_names())
    if (std::find(not_frame.begin(), not_frame.end(), name) == not_frame.end())
      if (auto v = args.opt(name)) pipeline::apply_frame_option(c, name, *v, "--" + name);
  try {
    pipeline::finish(c, args.has("budget"));
  } catch (const core::InputError& e) {
    throw core::InputError(std::string("--") + e.what());  // "--budget: must be in ..."
  }
  return c;
}

}  // namespace fovea::tools
