/*
 * insertion.c: a peg into a hole, written with macros over distance() as the manual's
 * programs were, on the simulated Microbo.
 *
 * The hole is HOLE on the table; the peg is held DEPTH mm into the gripper (TOOL). The macros
 * say the task: APPROACH above the hole, ENTER down to its mouth, PUSH the peg in slowly,
 * WAIT, PULL it out. Prints how deep the peg went, measured, and exits 1 if that is off by
 * 1.5 mm or more.
 *
 *   cc insertion.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 */
#include <stdio.h>
#include "rccl.h"
#include "rtc.h"

#define DEPTH 25.                                            /* mm into the hole */
#define APPROACH(p, mm) (setmod('j'), distance("dz", -(mm)), move(p))
#define ENTER(p) (setmod('c'), setvel(60., 60.), move(p))
#define PUSH(p, mm) (setvel(10., 10.), distance("dz", (mm)), move(p))
#define WAIT(ms) stop(ms)
#define PULL(p, mm) (setvel(60., 60.), distance("dz", -(mm)), move(p))

int main()
{
  TRSF_PTR table, hole, tool;
  POS_PTR at_hole;
  TRSF in, mouth;
  VECT d;
  double depth;

  table = gentr_rot("TABLE", 300., 0., 220., xunit, 180.);
  hole = gentr_trsl("HOLE", 10., 120., 0.);
  tool = gentr_trsl("TOOL", 0., 0., 45.);
  at_hole = makeposition("HOLE", t6, tool, EQ, table, hole, TL, tool);
  if (at_hole == NULL) return 1;

  if (rccl_open(0, 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  setvel(150., 90.);
  move(park);
  APPROACH(at_hole, 50.);
  ENTER(at_hole);
  waitfor(at_hole->end);
  PUSH(at_hole, DEPTH);
  waitfor(at_hole->end);
  trmult(&mouth, table, hole);
  trmult(&in, t6, tool);
  vecsub(&d, &in.p, &mouth.p);
  depth = dot(&d, &mouth.a); /* along the hole's axis (the tool's z) */
  printf("peg %.2f mm into the hole (asked %.0f mm)\n", depth, DEPTH);
  WAIT(300.);
  PULL(at_hole, 60.);
  setmod('j');
  move(park);
  waitfor(completed);
  if (rccl_close(0)) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  return depth > DEPTH - 1.5 && depth < DEPTH + 1.5 ? 0 : 1;
}
