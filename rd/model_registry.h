// The catalogue of reaction models, by scene name.
#pragma once

#include <string>
#include <vector>

#include "rd/reaction_model.h"

namespace morphoflow {

// Every model, in the order `morphoflow list models` prints them.
const std::vector<const ReactionModel*>& allModels();
// The model called `name`, or null.
const ReactionModel* findModel(const std::string& name);
std::vector<std::string> modelNames();
// Multi-line description: title, equations, species, parameters with defaults.
std::string describeModel(const ReactionModel& m);

}  // namespace morphoflow
