# The engine's source files, listed once, and the floating-point settings every build of them
# shares. Included by the top-level CMakeLists.txt (the native build, engine/CMakeLists.txt) and
# by engine/web/CMakeLists.txt (the live pages, which compile the same physics to WebAssembly).
# Paths are relative to engine/.

# The physics the lessons read (engine/clothlab/), folder by folder.
set(CLOTHLAB_PHYSICS_SOURCES
  clothlab/core/particles.cpp
  clothlab/core/world.cpp
  clothlab/core/step_timer.cpp
  clothlab/core/guard.cpp
  clothlab/core/threads.cpp
  clothlab/forces/gravity.cpp
  clothlab/forces/gravitation.cpp
  clothlab/forces/spring_damper.cpp
  clothlab/forces/bending.cpp
  clothlab/forces/damping.cpp
  clothlab/forces/aerodynamics.cpp
  clothlab/integrators/methods.cpp
  clothlab/integrators/euler.cpp
  clothlab/integrators/runge_kutta.cpp
  clothlab/integrators/verlet.cpp
  clothlab/integrators/implicit_euler.cpp
  clothlab/integrators/xpbd.cpp
  clothlab/integrators/local_global.cpp
  clothlab/integrators/vbd.cpp
  clothlab/bodies/cloth.cpp
  clothlab/bodies/rope.cpp
  clothlab/bodies/solid.cpp
  clothlab/bodies/normals.cpp
  clothlab/after_step/ground_collision.cpp
  clothlab/after_step/plasticity.cpp
  clothlab/after_step/tearing.cpp
  clothlab/after_step/strain_limiting.cpp
  clothlab/after_step/spatial_hash.cpp
  clothlab/after_step/self_collision.cpp
  clothlab/after_step/moving_pins.cpp)
# Around it: the scene reader and the game loop's driver, the analyses, and the engine room
# (the fast path behind World::backend: fast/engine.hpp, fast/SPEED.md).
set(CLOTHLAB_SCENE_SOURCES
  scene/scene.cpp
  scene/scene_tables.cpp
  scene/scene_warnings.cpp
  scene/simulation.cpp)
set(CLOTHLAB_ANALYSIS_SOURCES
  analysis/accuracy.cpp
  analysis/run_cost.cpp
  analysis/stability.cpp)
set(CLOTHLAB_FAST_SOURCES
  fast/engine.cpp
  fast/forces.cpp
  fast/springs.cpp
  fast/aerodynamics.cpp
  fast/xpbd.cpp
  fast/implicit.cpp
  fast/vbd.cpp
  fast/float_room.cpp)
# The engine room's parts that need CHOLMOD (libsuitesparse-dev): the native build only. The web
# module (engine/web/) leaves them out and runs the lecture's local/global loop, on Eigen's solver.
set(CLOTHLAB_FAST_CHOLMOD_SOURCES
  fast/local_global.cpp)
# What only the native program needs: runs, their files and the viewer page.
set(CLOTHLAB_IO_SOURCES
  io/run.cpp
  io/run_folder.cpp
  io/files.cpp
  io/output.cpp
  io/viewer.cpp
  io/npy.cpp
  io/json.cpp
  io/mesh_export.cpp)

# Floating point, for the fast path (engine/fast/), where the compiler evaluates the exercise
# kernels on several springs at once:
# - sqrt need not set errno, and a division need not be kept behind a branch for fear of a
#   floating-point trap nobody enables: both would keep the kernels' loops scalar;
# - Eigen's own SIMD code for 3-vectors is off: it packs x and y of one vector, which stops the
#   compiler from packing the same component of four springs (the wider win);
# - no fused multiply-adds: each operation is rounded as written, so the fast path, the readable
#   one, every processor and the browser's module give the same bits.
# None of this changes a result: it is IEEE arithmetic, operation for operation.
set(CLOTHLAB_FP_FLAGS -fno-math-errno -fno-trapping-math -ffp-contract=off
    -DEIGEN_DONT_VECTORIZE)
