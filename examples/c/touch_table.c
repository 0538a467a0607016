/*
 * touch_table.c: force in the manual's style (compat/rccl.h: limit, comply, lock, setload,
 * getcontact, updatecontact) on a PUMA 560 whose wrist has a sensor: the MuJoCo plant and a
 * table, which the robot file puma560_table.json describes.
 *
 *   t6 TOOL = TABLE SPOT          TABLE (hold): where the table is believed, its z up
 *                                 SPOT: a point on it, the tool pointing down
 *
 * 1. Touch: TABLE lowered 30 mm, a guarded move (limit("fz", 5.)) ends where the tool first
 *    presses 5 N (POS code RCCL_ONF); getcontact() says where, updatecontact() puts TABLE there.
 * 2. Wipe 150 mm along x, the path planned 5 mm into the table: comply("fz", 5.) lets the tool
 *    yield along its z and press 5 N, so it slides on the surface instead.
 * 3. comply("fz", 0.) to lift off, then lock("all") in the air and park.
 * Prints the contact and the wipe's depth; exits 1 when the contact is not within 0.5 mm of
 * the table's top (-203 mm in the file) or the tool went more than 1 mm into the table.
 *
 *   RCCX_ROBOT=examples/c/puma560_table.json ./build/release/examples/c_touch_table
 *
 * Built in rccx's tree it defaults to that file (TOUCH_TABLE_ROBOT); elsewhere, without
 * RCCX_ROBOT, it says how to run it and exits 2.
 */
#include <stdio.h>
#include <stdlib.h>
#include "rccl.h"
#include "rtc.h"

#define TABLE_TOP -203. /* mm, in the base frame (puma560_table.json) */
#define BELIEVED -200.  /* mm, where the program thinks it is */

int main()
{
  TRSF_PTR table, spot, lift, slide, tool;
  POS_PTR above, touch, along, leave;
  TRSF at, tip;
  double deepest = 1e9;

  if (getenv("RCCX_ROBOT") == 0) {
#ifdef TOUCH_TABLE_ROBOT
    setenv("RCCX_ROBOT", TOUCH_TABLE_ROBOT, 1);
#else
    fprintf(stderr, "touch_table: needs the PUMA 560 with a wrist sensor and a table\n"
                    "usage: RCCX_ROBOT=examples/c/puma560_table.json c_touch_table\n");
    return 2;
#endif
  }
  printf("robot file %s: a PUMA 560 with a wrist force sensor over a table\n",
         getenv("RCCX_ROBOT"));
  table = newtrans("TABLE", hold);
  table->p.z = BELIEVED;
  spot = gentr_rot("SPOT", 400., 100., 0., xunit, 180.);
  lift = gentr_trsl("LIFT", 0., 0., 30.);
  slide = gentr_trsl("SLIDE", 150., 0., -5.); /* 5 mm into the table */
  tool = gentr_trsl("TOOL", 0., 0., 100.);
  above = makeposition("ABOVE", t6, tool, EQ, table, lift, spot, TL, tool);
  touch = makeposition("TOUCH", t6, tool, EQ, table, spot, TL, tool);
  along = makeposition("ALONG", t6, tool, EQ, table, slide, spot, TL, tool);
  leave = makeposition("LEAVE", t6, tool, EQ, table, slide, lift, spot, TL, tool);

  if (rccl_open(0, 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  setload(0.4, 0., 0., 50.); /* the tool's weight out of the readings */
  move(above);
  waitfor(above->end);

  /* 1. Touch. */
  setmod('c');
  setvel(5., 30.); /* a search: slowly */
  limit("fz", 5.);
  table->p.z = BELIEVED - 30.; /* read at move(): the goal is 30 mm below */
  move(touch);
  waitfor(touch->end);
  limit("off");
  if (touch->code != RCCL_ONF || !getcontact(touch, &at)) {
    printf("no contact: the table is not where the program looked\n");
    rccl_close(0);
    return 1;
  }
  updatecontact(table, touch);
  printf("touched at z = %.2f mm (the table's top is at %.2f mm); TABLE at %.2f mm\n", at.p.z,
         TABLE_TOP, table->p.z);

  /* 2. Wipe, pressing. */
  comply("fz", 5.);
  setvel(20., 30.);
  move(along);
  while (!along->end) {
    if (rccl_wait_sample()) { /* control ended (the sensor saturated, ...) */
      print_rtc_error(rtc_error, 0);
      rccl_close(0);
      return 1;
    }
    Trmult(&tip, t6, tool);
    if (tip.p.z < deepest) deepest = tip.p.z;
  }
  printf("wiped 150 mm planned 5 mm into the table: the tool went %.2f mm into it\n",
         TABLE_TOP - deepest);

  /* 3. Leave: still compliant but asking for no force, so the tool lifts off with the offset
   * it took (locking now would pull it back to the path, 5 mm into the table); lock in the air. */
  comply("fz", 0.);
  move(leave);
  waitfor(leave->end);
  lock("all");
  setmod('j');
  move(park);
  waitfor(park->end);
  if (rccl_close(0)) return 1;
  if (at.p.z < TABLE_TOP - 0.5 || at.p.z > TABLE_TOP + 0.5 || TABLE_TOP - deepest > 1.) {
    printf("FAILED\n");
    return 1;
  }
  return 0;
}
