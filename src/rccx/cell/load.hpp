// A load for the cell's cycle: N robots of one kind on a square grid, each tracking a small
// circle in Cartesian mode through a functional transform (inverse kinematics and a functional
// evaluation every sample, collision checks between neighbours). What BM_CellCycle and
// `rccx cell-load` measure.
//
//   cell::Cell c(cell::grid_cell(16, "puma560", 1.5, 7ms));   // 4 x 4 PUMAs 1.5 m apart
//   cell::start_circles(c);                                    // starts c, queues every move
//   c.wait_for(10s);                                           // simulated time
#pragma once

#include <chrono>
#include <cstddef>
#include <string_view>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::cell {

/// `count` robots `robot` (a shipped robot) on a square grid `spacing_m` apart, every one at
/// `period`, with `link_radius_m` capsules and a 10 mm collision margin.
CellModel grid_cell(std::size_t count, std::string_view robot, double spacing_m,
                    std::chrono::nanoseconds period, double link_radius_m = 0.05);

/// Where start_circles puts the circle's centre (the wrist's), in each robot's base frame (the
/// PUMA's shoulder), m: 450 mm out, 50 mm aside and 150 mm below (example 05's reach).
inline constexpr math::Vec3 kCircleCentre_m{0.450, -0.050, -0.150};

/// Starts `cell` and sets every robot (a PUMA 560 or 260) moving: a joint move to a pose in
/// front of it, then, in Cartesian mode, onto a 20 mm circle around `centre_m` (in its base
/// frame) it goes round every 5 s for as long as the cell runs. Returns once every move is
/// queued. Throws rccl::MotionError when a robot cannot reach its circle. A cell denser than
/// the arm's reach may need another centre, so that the joint move from the ready pose keeps
/// clear of the next robot (bench/cell_bench.cpp's dense case).
void start_circles(Cell& cell, const math::Vec3& centre_m = kCircleCentre_m);

}  // namespace rccx::cell
