/// @file command_line.h
/// @brief The one command-line parser of the offline tools (calibrate_simulation, simulate,
/// evaluate, write_default_configs, render_sample): long options with typed values, range
/// checks, --help text, and errors that name the option.
#pragma once

#include <deque>
#include <functional>
#include <iosfwd>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace osc {

/// A command-line mistake (unknown option, missing or bad value, missing required option).
/// The message names the option; the tools print it followed by the usage text.
class CommandLineError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Declares options bound to variables, then parses argv into them.
///
///   osc::CommandLine cli("simulate", "Renders a simulated drive into a bag.");
///   cli.option("--out", &out, "DIR", "output directory").required();
///   cli.option("--frames", &frames, "N", "frames to render").range(1, 1e6);
///   if (!cli.parse(argc, argv)) return 0;  // --help was printed
///
/// Only the forms `--name VALUE` and `--name` (flags) are accepted; an option may take
/// several values (`--window FIRST LAST`). Values keep their defaults when an option is
/// not given; help() shows the defaults.
class CommandLine {
 public:
  /// One declared option; the setters return *this to chain.
  class Option {
   public:
    /// Parsing fails unless the option is given.
    Option& required();
    /// Numeric values must lie in [low, high] (the message names the option and the range).
    Option& range(double low, double high);
    /// The value must be one of @p choices.
    Option& choices(std::vector<std::string> choices);
    /// What help() shows as the default ("" shows none); the bound variable's value otherwise.
    Option& defaultText(std::string text);

   private:
    friend class CommandLine;
    std::string name, metavar, help, default_text;
    int arity = 1;  ///< values after the name; 0 for a flag
    bool is_required = false, given = false, numeric = false;
    double low = -std::numeric_limits<double>::infinity();
    double high = std::numeric_limits<double>::infinity();
    std::vector<std::string> allowed;
    /// Converts and stores the values; throws CommandLineError naming the option.
    std::function<void(const std::vector<std::string>&, const Option&)> store;
  };

  /// @p program and a one-paragraph @p description for help().
  CommandLine(std::string program, std::string description);

  /// A string option (`--name VALUE`).
  Option& option(const std::string& name, std::string* value, const std::string& metavar,
                 const std::string& help);
  /// An integer option; non-integers and values beyond int are errors.
  Option& option(const std::string& name, int* value, const std::string& metavar,
                 const std::string& help);
  /// A real option; non-numbers, NaN and infinities are errors.
  Option& option(const std::string& name, double* value, const std::string& metavar,
                 const std::string& help);
  /// An option of two integers (`--window FIRST LAST`).
  Option& option(const std::string& name, int* first, int* second, const std::string& metavar,
                 const std::string& help);
  /// A flag: sets *value to true when given.
  Option& flag(const std::string& name, bool* value, const std::string& help);
  /// Values without an option name (e.g. `write_default_configs CONFIG_DIR`): exactly
  /// @p count of them are required when count > 0.
  void positional(std::vector<std::string>* values, int count, const std::string& metavar,
                  const std::string& help);

  /// Parses argv. Returns false when -h/--help was given (help() has been written to
  /// @p help_out); true otherwise. @throws CommandLineError on any mistake.
  bool parse(int argc, const char* const* argv, std::ostream* help_out = nullptr);
  bool parse(int argc, char** argv, std::ostream* help_out = nullptr) {
    return parse(argc, const_cast<const char* const*>(argv), help_out);
  }
  /// Whether an option was given on the command line (after parse()).
  bool given(const std::string& name) const;

  /// Usage line, description and one line per option with its default.
  std::string help() const;
  /// The usage line alone.
  std::string usage() const;

 private:
  Option& add(Option option);
  const Option* find(const std::string& name) const;

  std::string program_, description_;
  std::deque<Option> options_;  ///< a deque: the references option() returns stay valid
  std::vector<std::string>* positional_ = nullptr;
  int positional_count_ = 0;
  std::string positional_metavar_, positional_help_;
};

/// Runs a tool's main body: returns its exit code; a CommandLineError prints
/// "PROGRAM: message" and the usage line (exit 2), any other exception "PROGRAM: message"
/// (exit 1).
int runTool(const std::string& program, const std::function<std::string()>& usage,
            const std::function<int()>& body);

}  // namespace osc
