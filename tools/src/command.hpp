#pragma once
// Subcommand registry and argument parsing shared by every `fovea` command.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace fovea::tools {

struct Command {
  std::string name;
  std::string summary;
  std::function<int(std::vector<std::string> args)> run;  // args after the command name
};

std::map<std::string, Command>& commands();

struct Registrar {
  Registrar(std::string name, std::string summary, std::function<int(std::vector<std::string>)> fn) {
    commands()[name] = Command{name, std::move(summary), std::move(fn)};
  }
};

#define FOVEA_COMMAND(var, name, summary, fn) \
  static const ::fovea::tools::Registrar var { name, summary, fn }

// `--key value`, `--key=value` and bare `--flag` parsing against a declared option set.
// Unknown options, missing values and stray positionals raise InputError naming them.
class Args {
 public:
  // `valued`: options that take a value; `flags`: options that do not.
  Args(const std::vector<std::string>& argv, const std::vector<std::string>& valued,
       const std::vector<std::string>& flags, int max_positional = 0);
  bool has(const std::string& key) const { return values_.count(key) != 0; }
  std::string str(const std::string& key, const std::string& fallback) const;
  std::optional<std::string> opt(const std::string& key) const;
  double num(const std::string& key, double fallback) const;
  long integer(const std::string& key, long fallback) const;
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};

bool stdout_is_tty();
bool stderr_is_tty();

}  // namespace fovea::tools
