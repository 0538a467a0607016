/*
 * monitor_wipe.c: stop on a surface with a monitor, then press and wipe, in the manual's style,
 * on a Microbo whose wrist has a sensor: the MuJoCo plant and a table, which the robot file
 * microbo_table.json describes.
 *
 *   t6 TOOL = SPOT MON            SPOT: a point over the table, the stylus pointing down
 *                                 MON: a functionally defined transform (the identity) whose
 *                                 function is a monitor: it sets nextmove once the measured
 *                                 stylus tip reaches the table's top
 *
 * 1. Search: down towards a goal 30 mm below the table; the monitor ends the motion where the
 *    arm is. The arm brakes past the touch: the command is left inside the table and the
 *    Microbo's stiff slide presses on (past 100 N within a second).
 * 2. comply("fz", 5.): the wipe that follows may start pressing more than its 100 N limit; it
 *    then yields toward the 5 N it is asked for first (a compliant motion fails only if it
 *    cannot within a second), and slides 60 mm along x pressing 5 N.
 * 3. comply("fz", 0.) to lift off, lock("all") in the air, and park.
 * Prints where the table was found and the depth the wipe kept; exits 1 when the search missed
 * the table or a motion failed.
 *
 *   RCCX_ROBOT=examples/c/microbo_table.json ./build/release/examples/c_monitor_wipe
 *
 * Built in rccx's tree it defaults to that file (MONITOR_WIPE_ROBOT); elsewhere, without
 * RCCX_ROBOT, it says how to run it and exits 2.
 */
#include <stdio.h>
#include <stdlib.h>
#include "rccl.h"
#include "rtc.h"

#define TABLE_TOP 190. /* mm, in the base frame (microbo_table.json) */
#define STYLUS 50.     /* mm, the tool along T6's z */

int touched = NO;
double touched_z = 0.;

int monitor(t) /* called every sample while the motion that uses MON runs */
TRSF_PTR t;
{
  (void)t;
  /* The measured T6 (t6), the stylus pointing down: its tip is STYLUS below. */
  if (!touched && t6->p.z - STYLUS <= TABLE_TOP) {
    touched = YES;
    touched_z = t6->p.z - STYLUS;
    nextmove = YES;
  }
  return 0;
}

int main()
{
  TRSF_PTR spot, down, along, lift, mon, tool;
  POS_PTR above, search, wipe, leave;
  TRSF tip;
  double shallowest = 1e9, deepest = -1e9;
  int failed = 0;

  if (getenv("RCCX_ROBOT") == 0) {
#ifdef MONITOR_WIPE_ROBOT
    setenv("RCCX_ROBOT", MONITOR_WIPE_ROBOT, 1);
#else
    fprintf(stderr, "monitor_wipe: needs the Microbo with a wrist sensor and a table\n"
                    "usage: RCCX_ROBOT=examples/c/microbo_table.json c_monitor_wipe\n");
    return 2;
#endif
  }
  printf("robot file %s: a Microbo with a wrist force sensor over a table\n",
         getenv("RCCX_ROBOT"));
  spot = gentr_rot("SPOT", 300., 0., TABLE_TOP + 20., xunit, 180.); /* 20 mm above, z down */
  down = gentr_trsl("DOWN", 0., 0., 50.);                              /* 30 mm below the top */
  along = newtrans("ALONG", hold); /* the wipe's end, set where the search stopped */
  lift = gentr_trsl("LIFT", 0., 0., -20.);
  mon = newtrans("MON", monitor);
  tool = gentr_trsl("TOOL", 0., 0., STYLUS);
  above = makeposition("ABOVE", t6, tool, EQ, spot, TL, tool);
  search = makeposition("SEARCH", t6, tool, EQ, spot, down, mon, TL, tool);
  wipe = makeposition("WIPE", t6, tool, EQ, along, TL, tool);
  leave = makeposition("LEAVE", t6, tool, EQ, along, lift, TL, tool);

  if (rccl_open(0, 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  setload(0.1, 0., 0., 25.); /* the stylus's weight out of the readings */
  move(above);
  waitfor(above->end);

  /* 1. Search. */
  setmod('c');
  setvel(5., 30.);
  move(search);
  waitfor(search->end);
  if (search->code != RCCL_NEXTMOVE || !touched) {
    printf("no touch: the search went to its end\n");
    rccl_close(0);
    return 1;
  }
  printf("touched at z = %.2f mm (the table's top is at %.0f mm)\n", touched_z, TABLE_TOP);

  /* 2. Wipe along x from where the arm stopped, pressing 5 N. */
  Trmult(&tip, t6, tool);
  Assigntr(along, &tip);
  along->p.x += 60.;
  comply("fz", 5.);
  setvel(10., 30.);
  move(wipe);
  while (!wipe->end) {
    if (rccl_wait_sample()) { /* control ended (the sensor saturated, ...) */
      print_rtc_error(rtc_error, 0);
      rccl_close(0);
      return 1;
    }
    Trmult(&tip, t6, tool);
    if (tip.p.z < shallowest) shallowest = tip.p.z;
    if (tip.p.z > deepest) deepest = tip.p.z;
  }
  failed = wipe->code == RTC_E_MOTION;
  printf("wiped 60 mm pressing 5 N: the stylus tip stayed between %.2f and %.2f mm "
         "(the table's top at %.0f mm)\n",
         shallowest, deepest, TABLE_TOP);

  /* 3. Leave, asking for no force; lock in the air. */
  comply("fz", 0.);
  move(leave);
  waitfor(leave->end);
  lock("all");
  setmod('j');
  move(park);
  waitfor(park->end);
  if (rccl_close(0)) return 1;
  if (failed) {
    printf("FAILED: the wipe failed\n");
    return 1;
  }
  return 0;
}
