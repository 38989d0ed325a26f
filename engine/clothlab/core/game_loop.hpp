// game_loop.hpp: driving the engine from a game or an interactive program (lesson 11).
//
// Game-physics lecture, "game engine interface": the game owns the clock and the screen, the
// engine owns the physics. A game's frames last whatever the machine makes them (16.7 ms at
// 60 fps, 33 ms at 30 fps, a 200 ms hitch now and then), but the engine must always step by
// the scene's dt: a larger step may be unstable (lesson 08), and a step that changes with the
// frame rate makes the motion depend on the machine. So a frame's time goes into an
// accumulator, and the engine takes as many whole steps of dt (substeps) as it holds:
//
//   accumulator += frame_time
//   while accumulator >= dt:  step(dt), accumulator -= dt
//
// The time left over, less than one dt, waits for the next frame. What the game draws lies
// between the last two states, alpha = leftover / dt of the way from the older to the newer.
//
// Determinism. The substeps a sequence of frames takes depends only on the total time, not on
// how it was cut into frames: 120 frames of 1/60 s, 60 of 1/30 s and one of 2 s all take 1200
// steps of dt = 1/600 s. In floating point 1/60 and 1/600 are not exact, and the leftover after
// "10 steps" can come out as -1e-19 s or as dt - 1e-19 s; the second would delay a step by a
// whole frame. So a time within kStepTolerance * dt short of a whole step counts as that step,
// and the leftover it leaves (a rounding error, never more than that tolerance) is taken as 0.
// The leftover stays below dt, so rounding errors never grow with the length of the run.
//
// The spiral of death. If a step costs more wall time than the dt it simulates, each frame
// lasts longer than the one before and asks for yet more steps. A cap on the substeps of one
// frame breaks the loop: the time beyond it is dropped (the game slows down instead of
// freezing), and dropped_time() says how much.
//
// This file holds the accumulator's arithmetic, the part the lesson's exercise writes; the
// driver that steps a scene with it (Simulation: pins dragged, wind ramped, positions
// interpolated for drawing) is scene/simulation.hpp.
#pragma once

namespace clothlab {

// A time this close to a whole number of steps, as a fraction of dt, counts as that number.
// 1e-6 dt is a millionth of a step: far above the rounding of a sum of frame times (about
// 1e-16 dt per frame, and the leftover is reset at every whole step), far below anything a
// clock measures or a player notices.
inline constexpr double kStepTolerance = 1e-6;

// What one frame asks of the engine.
struct Substeps {
  long count = 0;         // whole steps of dt to take now
  double leftover = 0.0;  // time carried to the next frame [s], in [0, dt)
  double dropped = 0.0;   // time given up because the steps due exceeded the cap [s]
};

// Exercise ex11.1: the accumulator's arithmetic for one frame. `leftover` [s] is what the last
// frame left, `frame_time` [s] this frame's time (both >= 0), `dt` [s] the step and
// `max_substeps` (>= 1) the cap. The steps due are the whole steps of dt in leftover +
// frame_time, a time within kStepTolerance * dt short of a step counting as that step; at most
// max_substeps are taken and the whole steps beyond the cap are dropped; the fraction of a step
// that remains is the new leftover.
Substeps accumulate(double leftover, double frame_time, double dt, long max_substeps);

}  // namespace clothlab
