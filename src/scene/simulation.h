// The simulation clock of a scene: its particle systems, cloth and flocks
// advanced together in steps of 1 / (fps * substeps) seconds, with one
// wind field acting on all of them (through each system's drag, each
// cloth's aerodynamic force and each flock's steering).
//
//   auto sim = scene::Simulation::Create(scene, built, options, diagnostics);
//   if (Status s = (*sim)->AdvanceTo(5.0); !s.ok()) ...
//   draw::DrawList list = scene::MakeDrawList(scene, built);
//   (*sim)->AddToDrawList(list);
//
// Particles are particles::System (double precision), one per <particles>,
// each with its forces (gravity, drag through the wind, attractor, vortex,
// noise), colliders (`ground`: the plane y = 0; a terrain: its triangle
// mesh; a plant or forest: its tube and leaf triangles, through a bounding
// hierarchy) and emitters (shapes point, sphere, box, disc, terrain and
// plant parts; births spread over each step). <on-death> emits into another
// system where a particle dies. Everything random is drawn from
// counter-based streams keyed by the scene's seed, the element and the
// particle, so a run is the same for any thread count.
#pragma once

#include <iosfwd>
#include <memory>
#include <vector>

#include "core/diagnostic.h"
#include "core/status.h"
#include "draw/draw_list.h"
#include "scene/build.h"
#include "scene/scene.h"

namespace sylva::scene {

struct SimulationOptions {
  // The process's pool (core/parallel.h SharedPool), shared by every
  // particle system, cloth and flock; null: a pool of `threads` each.
  ThreadPool* pool = nullptr;
  int threads = 1;  // without a pool; 0: all cores
};

inline constexpr double kMaxStepsPerAdvance = 1e7;

class Simulation {
 public:
  // Builds the systems; warnings (features read but not simulated) go to
  // `diagnostics`. An error (a bad combination found only now) is returned.
  static Expected<std::unique_ptr<Simulation>> Create(const Scene& scene, const BuiltScene& built,
                                                      const SimulationOptions& options,
                                                      DiagnosticList& diagnostics);
  ~Simulation();

  double time() const;
  double stepLength() const;
  // Steps until time() >= t (to within half a step). An explosion or a
  // failed step is an error naming the element and the time; more than
  // kMaxStepsPerAdvance steps is an input error before any step.
  [[nodiscard]] Status AdvanceTo(double t);
  // Warnings of steps taken (a particle system's collisions that did not
  // converge in a step: System::pairMaxPasses), the first of each element,
  // with its location; the simulation went on.
  const DiagnosticList& warnings() const;
  // Particles as sprites, lines or instanced meshes; cloth as meshes; boids
  // as instanced meshes.
  void AddToDrawList(draw::DrawList& list) const;
  // Every particle of every system, every cloth vertex and boid, as CSV
  // with the header `system,id,x,y,z,vx,vy,vz,age`.
  void WriteCsv(std::ostream& out) const;
  // Live particles of every system, cloth vertices and boids.
  size_t Count() const;

 private:
  Simulation();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva::scene
