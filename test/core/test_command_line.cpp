/// Tests of the offline tools' one argument parser (command_line.h): typed values and
/// defaults, errors naming the option, the help text, positional arguments and exit codes.
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "online_stereo_calibration/tools/command_line.h"

namespace osc {
namespace {

/// Parses a list of words (argv[0] is added) and returns the error message, "" on success,
/// "help" when --help was asked for.
std::string parseWords(CommandLine* cli, std::vector<std::string> words,
                       std::ostream* help_out = nullptr) {
  words.insert(words.begin(), "tool");
  std::vector<const char*> argv;
  for (const std::string& w : words) argv.push_back(w.c_str());
  std::ostringstream sink;
  try {
    return cli->parse(static_cast<int>(argv.size()), argv.data(), help_out ? help_out : &sink)
               ? ""
               : "help";
  } catch (const CommandLineError& e) {
    return e.what();
  }
}

struct ToolOptions {
  std::string out, mode = "fast";
  int frames = 100;
  double rate = 2.5;
  int first = 1000, last = 1150;
  bool verbose = false;
  int hidden = -1;
};

CommandLine makeCli(ToolOptions* o) {
  CommandLine cli("tool", "Does a thing.");
  cli.option("--out", &o->out, "DIR", "output directory").required();
  cli.option("--frames", &o->frames, "N", "frames").range(1, 100000);
  cli.option("--rate", &o->rate, "HZ", "rate").range(0.0, 1000.0);
  cli.option("--mode", &o->mode, "MODE", "mode").choices({"fast", "slow"});
  cli.option("--window", &o->first, &o->last, "FIRST LAST", "window").range(0, 1e9);
  cli.flag("--verbose", &o->verbose, "talk");
  cli.option("--hidden", &o->hidden, "N", "no default shown").defaultText("");
  return cli;
}

TEST(CommandLine, TypedValuesAndDefaults) {
  ToolOptions o;
  CommandLine cli = makeCli(&o);
  EXPECT_EQ(parseWords(&cli, {"--out", "d", "--frames", "42", "--rate", "-0", "--window", "3", "7",
                              "--verbose", "--mode", "slow"}),
            "");
  EXPECT_EQ(o.out, "d");
  EXPECT_EQ(o.frames, 42);
  EXPECT_DOUBLE_EQ(o.rate, 0.0);
  EXPECT_EQ(o.first, 3);
  EXPECT_EQ(o.last, 7);
  EXPECT_TRUE(o.verbose);
  EXPECT_EQ(o.mode, "slow");
  EXPECT_TRUE(cli.given("--frames"));

  ToolOptions d;
  CommandLine defaults = makeCli(&d);
  EXPECT_EQ(parseWords(&defaults, {"--out", "x"}), "");
  EXPECT_EQ(d.frames, 100);
  EXPECT_DOUBLE_EQ(d.rate, 2.5);
  EXPECT_EQ(d.first, 1000);
  EXPECT_FALSE(d.verbose);
  EXPECT_FALSE(defaults.given("--frames"));
}

TEST(CommandLine, ErrorsNameTheOption) {
  const auto error = [](std::vector<std::string> words) {
    ToolOptions o;
    CommandLine cli = makeCli(&o);
    return parseWords(&cli, std::move(words));
  };
  EXPECT_EQ(error({"--out", "d", "--framez", "3"}),
            "unknown option '--framez' (--help lists the options)");
  EXPECT_EQ(error({"--frames", "3"}), "missing required option(s): --out");
  EXPECT_EQ(error({"--out"}), "--out needs a value (DIR)");
  EXPECT_EQ(error({"--out", "d", "--window", "3"}), "--window needs 2 values (FIRST LAST)");
  EXPECT_EQ(error({"--out", "d", "--frames", "12x"}), "--frames: '12x' is not an integer");
  EXPECT_EQ(error({"--out", "d", "--frames", "99999999999"}),
            "--frames: '99999999999' is not an integer");
  EXPECT_EQ(error({"--out", "d", "--frames", "0"}), "--frames: 0 is outside [1, 100000]");
  EXPECT_EQ(error({"--out", "d", "--rate", "nan"}), "--rate: 'nan' is not a finite number");
  EXPECT_EQ(error({"--out", "d", "--rate", "1e9"}), "--rate: 1e9 is outside [0, 1000]");
  EXPECT_EQ(error({"--out", "d", "--window", "5", "-1"}),
            "--window: -1 is outside [0, 1000000000]");
  EXPECT_EQ(error({"--out", "d", "--mode", "medium"}), "--mode: 'medium' is not one of fast, slow");
  EXPECT_EQ(error({"--out", "d", "--out", "e"}), "--out given twice");
  EXPECT_EQ(error({"--out", "d", "stray"}), "unexpected argument 'stray'");
  EXPECT_EQ(error({"--out=d"}), "--out: write '--out VALUE', not '--out=d'");
}

TEST(CommandLine, HelpListsEveryOptionWithDefaultsAndRanges) {
  ToolOptions o;
  CommandLine cli = makeCli(&o);
  std::ostringstream help;
  EXPECT_EQ(parseWords(&cli, {"--frames", "5", "--help"}, &help), "help");
  const std::string text = help.str();
  EXPECT_EQ(text, cli.help());
  EXPECT_EQ(text.rfind("usage: tool --out DIR [--frames N]", 0), 0u) << text;
  EXPECT_NE(text.find("Does a thing."), std::string::npos);
  EXPECT_NE(text.find("--frames N"), std::string::npos);
  EXPECT_NE(text.find("[1, 100000]; default 100"), std::string::npos) << text;
  EXPECT_NE(text.find("{fast|slow}; default fast"), std::string::npos) << text;
  EXPECT_NE(text.find("(required)"), std::string::npos);
  EXPECT_NE(text.find("--window FIRST LAST"), std::string::npos);
  EXPECT_NE(text.find("-h, --help"), std::string::npos);
  EXPECT_NE(text.find("no default shown\n"), std::string::npos) << text;
  for (const std::string& line : {cli.usage()}) {
    std::istringstream lines(line);
    std::string l;
    while (std::getline(lines, l)) EXPECT_LE(l.size(), 100u) << l;
  }
}

TEST(CommandLine, PositionalArguments) {
  std::vector<std::string> dirs;
  CommandLine cli("write", "Writes.");
  cli.positional(&dirs, 1, "CONFIG_DIR", "where");
  EXPECT_EQ(parseWords(&cli, {"config"}), "");
  ASSERT_EQ(dirs.size(), 1u);
  EXPECT_EQ(dirs[0], "config");
  EXPECT_EQ(parseWords(&cli, {}), "expected 1 CONFIG_DIR, got 0");
  EXPECT_EQ(parseWords(&cli, {"a", "b"}), "expected 1 CONFIG_DIR, got 2");
  EXPECT_EQ(parseWords(&cli, {"--x"}), "unknown option '--x' (--help lists the options)");
}

TEST(CommandLine, RunToolMapsErrorsToExitCodes) {
  EXPECT_EQ(runTool(
                "t", [] { return std::string("usage: t\n"); }, [] { return 0; }),
            0);
  EXPECT_EQ(runTool(
                "t", [] { return std::string("usage: t\n"); },
                []() -> int { throw CommandLineError("bad"); }),
            2);
  EXPECT_EQ(runTool(
                "t", [] { return std::string("usage: t\n"); },
                []() -> int { throw std::runtime_error("io"); }),
            1);
}

}  // namespace
}  // namespace osc
