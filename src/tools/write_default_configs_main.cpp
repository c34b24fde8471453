// Writes config/default.yaml and config/paper.yaml from the code's defaults (the filter's
// keys from filterParameterTable(), the front end's `front_end:` section from
// frontEndParameterTable()), so the files and the code cannot disagree
// (test_filter_config_yaml checks that they are up to date).
//   write_default_configs CONFIG_DIR
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/estimator_config_yaml.h"
#include "online_stereo_calibration/tools/output_directory.h"

int main(int argc, char** argv) {
  std::vector<std::string> directories;
  osc::CommandLine cli("write_default_configs",
                       "Writes CONFIG_DIR/default.yaml (the shipped defaults) and "
                       "CONFIG_DIR/paper.yaml (the seed's values)\nfrom the code.");
  cli.positional(&directories, 1, "CONFIG_DIR", "directory to write into (e.g. config)");
  return osc::runTool(
      "write_default_configs", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return 0;
        const std::string dir = directories.front();
        osc::EstimatorConfig paper;
        paper.filter = osc::paperFilterConfig();
        osc::writeTextFileAtomic(dir + "/default.yaml",
                                 osc::formatEstimatorConfigYaml(
                                     osc::EstimatorConfig(),
                                     "online_stereo_calibration: shipped defaults (docs/RESULTS.md "
                                     "has the figures behind every value that differs from "
                                     "paper.yaml)"));
        osc::writeTextFileAtomic(dir + "/paper.yaml",
                                 osc::formatEstimatorConfigYaml(
                                     paper,
                                     "online_stereo_calibration: the seed paper's values (Mueller "
                                     "& Wuensche 2016, eq. 10-15); values the paper does not give "
                                     "are our defaults"));
        std::cout << "wrote " << dir << "/default.yaml and " << dir << "/paper.yaml\n";
        return 0;
      });
}
