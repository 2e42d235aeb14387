// A filter's input as the front ends fill it, for the engine tests: a
// shipped scene's mesh and attributes, and the filter's default parameters
// for that mesh's size.
#pragma once
#include "gi/filter_run.h"
#include "gi/scenes.h"

namespace gi::test {

inline FilterInput filterInput(FilterKind kind, const scenes::SceneFile& sf) {
  FilterInput in;
  in.scene = sf.scene;
  in.attrs = sf.attrs;
  in.values = defaultValues(filterSpecs(kind), analyzeScene(in.scene).diagonal);
  return in;
}

}  // namespace gi::test
