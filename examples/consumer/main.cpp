// plant_to_obj GRAMMAR OUT.obj [STEPS]: a plant mesh from a grammar, in one
// call to the installed Sylva plant library.
#include <cstdlib>
#include <iostream>

#include "mesh/export.h"
#include "plant/plant.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: plant_to_obj GRAMMAR OUT.obj [STEPS]\n";
    return 2;
  }
  sylva::plant::PlantSpec spec;
  spec.path = argv[1];
  if (argc > 3) spec.steps = std::atoi(argv[3]);
  spec.detail.sides = 6;
  sylva::plant::PlantResult r = sylva::plant::BuildPlant(spec);
  std::cerr << r.diagnostics.FormatAll();  // warnings, or the errors
  if (!r.plant) return 2;
  if (sylva::Status s = sylva::mesh::WriteMesh(r.plant->mesh, r.plant->palette, argv[2]); !s.ok()) {
    std::cerr << s.error().Format();
    return 1;
  }
  std::cout << argv[2] << ": " << r.plant->mesh.triangleCount() << " triangles\n";
  return 0;
}
