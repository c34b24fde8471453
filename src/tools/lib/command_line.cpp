/// @file command_line.cpp
/// @brief The offline tools' command-line parser.
#include "online_stereo_calibration/tools/command_line.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace osc {
namespace {

std::string formatNumber(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

long parseInteger(const std::string& text, const std::string& option) {
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || v < INT_MIN || v > INT_MAX) {
    throw CommandLineError(option + ": '" + text + "' is not an integer");
  }
  return v;
}

double parseReal(const std::string& text, const std::string& option) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
    throw CommandLineError(option + ": '" + text + "' is not a finite number");
  }
  return v;
}

void checkRange(double v, const std::string& text, double low, double high,
                const std::string& name) {
  if (v < low || v > high) {
    throw CommandLineError(name + ": " + text + " is outside [" + formatNumber(low) + ", " +
                           formatNumber(high) + "]");
  }
}

}  // namespace

CommandLine::Option& CommandLine::Option::required() {
  is_required = true;
  return *this;
}

CommandLine::Option& CommandLine::Option::range(double low_value, double high_value) {
  low = low_value;
  high = high_value;
  return *this;
}

CommandLine::Option& CommandLine::Option::choices(std::vector<std::string> values) {
  allowed = std::move(values);
  return *this;
}

CommandLine::Option& CommandLine::Option::defaultText(std::string text) {
  default_text = std::move(text);
  return *this;
}

CommandLine::CommandLine(std::string program, std::string description)
    : program_(std::move(program)), description_(std::move(description)) {}

CommandLine::Option& CommandLine::add(Option option) {
  if (option.name.size() < 3 || option.name.compare(0, 2, "--") != 0) {
    throw std::logic_error("option names start with --: '" + option.name + "'");
  }
  if (find(option.name)) throw std::logic_error("option declared twice: " + option.name);
  options_.push_back(std::move(option));
  return options_.back();
}

const CommandLine::Option* CommandLine::find(const std::string& name) const {
  for (const Option& o : options_) {
    if (o.name == name) return &o;
  }
  return nullptr;
}

CommandLine::Option& CommandLine::option(const std::string& name, std::string* value,
                                         const std::string& metavar, const std::string& help) {
  Option o;
  o.name = name;
  o.metavar = metavar;
  o.help = help;
  o.default_text = value->empty() ? "" : *value;
  o.store = [value](const std::vector<std::string>& v, const Option& self) {
    if (!self.allowed.empty() &&
        std::find(self.allowed.begin(), self.allowed.end(), v[0]) == self.allowed.end()) {
      std::string list;
      for (const std::string& c : self.allowed) list += (list.empty() ? "" : ", ") + c;
      throw CommandLineError(self.name + ": '" + v[0] + "' is not one of " + list);
    }
    *value = v[0];
  };
  return add(std::move(o));
}

CommandLine::Option& CommandLine::option(const std::string& name, int* value,
                                         const std::string& metavar, const std::string& help) {
  Option o;
  o.name = name;
  o.metavar = metavar;
  o.help = help;
  o.numeric = true;
  o.default_text = std::to_string(*value);
  o.store = [value](const std::vector<std::string>& v, const Option& self) {
    const long x = parseInteger(v[0], self.name);
    checkRange(static_cast<double>(x), v[0], self.low, self.high, self.name);
    *value = static_cast<int>(x);
  };
  return add(std::move(o));
}

CommandLine::Option& CommandLine::option(const std::string& name, double* value,
                                         const std::string& metavar, const std::string& help) {
  Option o;
  o.name = name;
  o.metavar = metavar;
  o.help = help;
  o.numeric = true;
  o.default_text = formatNumber(*value);
  o.store = [value](const std::vector<std::string>& v, const Option& self) {
    const double x = parseReal(v[0], self.name);
    checkRange(x, v[0], self.low, self.high, self.name);
    *value = x;
  };
  return add(std::move(o));
}

CommandLine::Option& CommandLine::option(const std::string& name, int* first, int* second,
                                         const std::string& metavar, const std::string& help) {
  Option o;
  o.name = name;
  o.metavar = metavar;
  o.help = help;
  o.numeric = true;
  o.arity = 2;
  o.default_text = std::to_string(*first) + " " + std::to_string(*second);
  o.store = [first, second](const std::vector<std::string>& v, const Option& self) {
    const long a = parseInteger(v[0], self.name);
    const long b = parseInteger(v[1], self.name);
    checkRange(static_cast<double>(a), v[0], self.low, self.high, self.name);
    checkRange(static_cast<double>(b), v[1], self.low, self.high, self.name);
    *first = static_cast<int>(a);
    *second = static_cast<int>(b);
  };
  return add(std::move(o));
}

CommandLine::Option& CommandLine::flag(const std::string& name, bool* value,
                                       const std::string& help) {
  Option o;
  o.name = name;
  o.help = help;
  o.arity = 0;
  o.store = [value](const std::vector<std::string>&, const Option&) { *value = true; };
  return add(std::move(o));
}

void CommandLine::positional(std::vector<std::string>* values, int count,
                             const std::string& metavar, const std::string& help) {
  positional_ = values;
  positional_count_ = count;
  positional_metavar_ = metavar;
  positional_help_ = help;
}

bool CommandLine::parse(int argc, const char* const* argv, std::ostream* help_out) {
  for (Option& o : options_) o.given = false;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      (help_out ? *help_out : std::cout) << help();
      return false;
    }
    if (a.size() > 1 && a[0] == '-' &&
        !(a.size() > 1 && (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.'))) {
      Option* o = const_cast<Option*>(find(a));
      if (!o) {
        const std::string bare = a.substr(0, a.find('='));
        if (bare != a && find(bare)) {
          throw CommandLineError(bare + ": write '" + bare + " VALUE', not '" + a + "'");
        }
        throw CommandLineError("unknown option '" + a + "' (--help lists the options)");
      }
      if (o->given) throw CommandLineError(o->name + " given twice");
      std::vector<std::string> values;
      for (int k = 0; k < o->arity; ++k) {
        if (i + 1 >= argc) {
          throw CommandLineError(
              o->name + " needs " +
              (o->arity == 1 ? "a value" : std::to_string(o->arity) + " values") + " (" +
              o->metavar + ")");
        }
        values.push_back(argv[++i]);
      }
      o->store(values, *o);
      o->given = true;
      continue;
    }
    positional.push_back(a);
  }
  if (!positional.empty() && !positional_) {
    throw CommandLineError("unexpected argument '" + positional.front() + "'");
  }
  if (positional_) {
    if (positional_count_ > 0 && static_cast<int>(positional.size()) != positional_count_) {
      throw CommandLineError("expected " + std::to_string(positional_count_) + " " +
                             positional_metavar_ + ", got " + std::to_string(positional.size()));
    }
    *positional_ = positional;
  }
  std::string missing;
  for (const Option& o : options_) {
    if (o.is_required && !o.given) missing += (missing.empty() ? "" : ", ") + o.name;
  }
  if (!missing.empty()) throw CommandLineError("missing required option(s): " + missing);
  return true;
}

bool CommandLine::given(const std::string& name) const {
  const Option* o = find(name);
  if (!o) throw std::logic_error("no option " + name);
  return o->given;
}

std::string CommandLine::usage() const {
  std::string line = "usage: " + program_;
  for (const Option& o : options_) {
    std::string part = o.name + (o.metavar.empty() ? "" : " " + o.metavar);
    line += " " + (o.is_required ? part : "[" + part + "]");
  }
  if (positional_) line += " " + positional_metavar_;
  // Wrap at 100 columns, keeping each "[--x VALUE]" or "--x VALUE" group on one line.
  std::string out;
  std::size_t column = 0;
  const std::string indent(8, ' ');
  std::vector<std::string> groups;
  std::size_t start = 0;
  int depth = 0;
  for (std::size_t k = 0; k < line.size(); ++k) {
    if (line[k] == '[') ++depth;
    if (line[k] == ']') --depth;
    if (line[k] == ' ' && depth == 0 && k + 2 < line.size() &&
        (line[k + 1] == '[' || (line[k + 1] == '-' && line[k + 2] == '-'))) {
      groups.push_back(line.substr(start, k - start));
      start = k + 1;
    }
  }
  groups.push_back(line.substr(start));
  for (const std::string& g : groups) {
    if (column > 0 && column + 1 + g.size() > 100) {
      out += "\n" + indent;
      column = indent.size();
    } else if (column > 0) {
      out += " ";
      ++column;
    }
    out += g;
    column += g.size();
  }
  return out + "\n";
}

std::string CommandLine::help() const {
  std::ostringstream s;
  s << usage() << "\n" << description_ << "\n\noptions:\n";
  // "  --name VALUE   help text", the text wrapped at 100 columns under column 30.
  constexpr std::size_t kColumn = 30, kWidth = 100;
  const auto line = [&](const std::string& left, const std::string& text) {
    s << "  " << left;
    std::size_t column = 2 + left.size();
    if (column + 2 > kColumn) {
      s << "\n";
      column = 0;
    }
    s << std::string(kColumn - column, ' ');
    column = kColumn;
    std::istringstream words(text);
    std::string word;
    bool first = true;
    while (words >> word) {
      if (!first && column + 1 + word.size() > kWidth) {
        s << "\n" << std::string(kColumn, ' ');
        column = kColumn;
      } else if (!first) {
        s << ' ';
        ++column;
      }
      s << word;
      column += word.size();
      first = false;
    }
    s << "\n";
  };
  for (const Option& o : options_) {
    std::string text = o.help;
    if (o.is_required) text += " (required)";
    if (!o.allowed.empty()) {
      std::string list;
      for (const std::string& c : o.allowed) list += (list.empty() ? "" : "|") + c;
      text += " {" + list + "}";
    }
    if (o.numeric && (std::isfinite(o.low) || std::isfinite(o.high))) {
      text += " [" + formatNumber(o.low) + ", " + formatNumber(o.high) + "]";
    }
    if (!o.is_required && o.arity > 0 && !o.default_text.empty()) {
      text += "; default " + o.default_text;
    }
    line(o.name + (o.metavar.empty() ? "" : " " + o.metavar), text);
  }
  if (positional_) line(positional_metavar_, positional_help_);
  line("-h, --help", "this text");
  return s.str();
}

int runTool(const std::string& program, const std::function<std::string()>& usage,
            const std::function<int()>& body) {
  try {
    return body();
  } catch (const CommandLineError& e) {
    std::cerr << program << ": " << e.what() << "\n" << usage();
    return 2;
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace osc
