/*
 * pick_place.c: pick and place in the manual's style, on the simulated Microbo.
 *
 * A gripper (TOOL, 40 mm along the wrist's z) picks three parts from a row on the table and
 * puts them on a pile. The part to take is a hold transform PART: the program sets it before
 * each move(), and each queued motion keeps the value it had then. Approaches and departures
 * are Cartesian (distance() in the tool's z), the carries are joint moves that also turn the
 * wrist. Prints where each part was put, measured, and exits 1 if it is off by 2 mm or more.
 *
 *   cc pick_place.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 */
#include <math.h>
#include <stdio.h>
#include "rccl.h"
#include "rtc.h"

#define APPROACH 40. /* mm above a part along the tool's z */

/* Distance (mm) from the measured T6 TOOL to where the tool should be. */
double tool_error(tool, goal)
TRSF_PTR tool, goal;
{
  TRSF now;
  VECT d;
  Trmult(&now, t6, tool);
  Vecsub(&d, &now.p, &goal->p);
  return norm(&d);
}

int main()
{
  TRSF_PTR table, tool, part, pile;
  POS_PTR get, put;
  TRSF where;
  int i, bad = 0;

  table = gentr_rot("TABLE", 300., 0., 220., xunit, 180.); /* z down onto the table */
  tool = gentr_trsl("TOOL", 0., 0., 40.);
  part = newtrans("PART", hold);
  pile = newtrans("PILE", hold);

  /* T6 TOOL = TABLE PART and T6 TOOL = TABLE PILE */
  get = makeposition("GET", t6, tool, EQ, table, part, TL, tool);
  put = makeposition("PUT", t6, tool, EQ, table, pile, TL, tool);
  if (get == NULL || put == NULL) return 1;

  if (rccl_open(0, 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  setvel(150, 90);
  move(park);
  waitfor(park->end);

  for (i = 0; i < 3; i++) {
    Trsl(part, 0., 100. + 40. * i, 0.); /* the i-th part of the row */
    Trsl(pile, 0., -150., -10. * i);     /* the pile grows by 10 mm a part (z is down) */
    Rotr(pile, zunit, 90.);              /* parts go on it turned 90 deg */
    setmod('j');
    distance("dz", -APPROACH);
    move(get); /* above the part */
    setmod('c');
    move(get); /* down */
    waitfor(get->end);
    printf("part %d grasped, off by %.2f mm\n", i + 1,
           tool_error(tool, trmult(&where, table, part)));
    distance("dz", -APPROACH);
    move(get); /* up: a Cartesian departure ... */
    setmod('j');
    distance("dz", -APPROACH);
    move(put); /* ... blended into the carry and the wrist's turn */
    setmod('c');
    move(put); /* down onto the pile */
    waitfor(put->end);
    trmult(&where, table, pile);
    printf("part %d put at (%.1f, %.1f, %.1f) mm, off by %.2f mm\n", i + 1, where.p.x,
           where.p.y, where.p.z, tool_error(tool, &where));
    if (tool_error(tool, &where) >= 2.) bad = 1;
    distance("dz", -APPROACH);
    move(put);
  }
  setmod('j');
  move(park);
  waitfor(completed);
  if (rccl_close(0)) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  return bad;
}
