/// @file parameter_section.h
/// @brief A section of the configuration: the component that uses a group of keys. The
/// parameter tables (filterParameterTable(), frontEndParameterTable()) give every key a
/// section and an audience; config/default.yaml and docs/configuration.md list the keys by
/// them, a user's keys first.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace osc {

/// One section of a parameter table, in the order the generated files list them.
struct ParameterSection {
  std::string name;         ///< e.g. "rig and noise"; the value of a row's `section`
  std::string description;  ///< one line for the files' banner: what the keys are for
};

/// Throws std::logic_error naming the first row of @p table (ParameterSpec or
/// FrontEndParameterSpec) whose `section` is not one of @p sections: a key without a section
/// would be left out of the generated files, so the tables check this when first built.
template <class Spec>
void requireKnownSections(const std::vector<Spec>& table,
                          const std::vector<ParameterSection>& sections,
                          const std::string& table_name) {
  for (const Spec& spec : table) {
    bool known = false;
    for (const ParameterSection& section : sections) known = known || section.name == spec.section;
    if (!known) {
      throw std::logic_error(table_name + ": key " + spec.name + " has section '" + spec.section +
                             "', which is not one of its sections");
    }
  }
}

}  // namespace osc
