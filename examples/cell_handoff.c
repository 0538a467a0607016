/*
 * Two robots from one C program (the CVaRL cell: a PUMA 260 and the Microbo over the circuit
 * board), through RCCL's C names with a robot handle each (compat/rccl.h, "Several robots"):
 *
 *   1. both arms go above the board at once (joint mode);
 *   2. a hand-off: the Microbo's motion starts only once the PUMA's has ended (mnp_after);
 *   3. a joint start that also ends together: the PUMA's short move is slowed to the Microbo's
 *      longer one (rccl_together).
 *
 * Lengths in mm, angles in degrees, as in 1986. Written in the C of the time (declarations
 * first, no // comments): it compiles with -std=gnu89.
 */
#include <stdio.h>

#include "rccl.h"
#include "rtc.h"

static int check(int code, const char* what)
{
  if (code != 0) printf("%s: error %s\n", what, rtc_error_name(code));
  return code;
}

int main(void)
{
  MANIP *puma, *mbo;
  TRSF_PTR pw, pw2, mw, mw2;
  POS_PTR p, p2, m, m2;
  int a, b, order_ok;

  if (check(rccl_cell_open((char*)0), "rccl_cell_open")) return 1;
  puma = rcclCreate("puma", 0);
  mbo = rcclCreate("microbo", 0);
  if (puma == 0 || mbo == 0 || check(rcclStart(), "rcclStart")) return 1;

  /* World goals, tool pointing down (180 deg about x), 50 mm above the board's face. */
  pw = gen_tr_rot("PW", -50., 0., 151.6, xunit, 180.);
  pw2 = gen_tr_rot("PW2", -50., 10., 151.6, xunit, 180.);
  mw = gen_tr_rot("MW", 100., 0., 151.6, xunit, 180.);
  mw2 = gen_tr_rot("MW2", 100., 60., 151.6, xunit, 180.);
  /* T6 TOOL = BASE^-1 WORLD_GOAL, for each robot in its own base frame. */
  p = makeposition("P", t6, mnp_tool(puma), EQ, mnp_base_inv(puma), pw, TL, mnp_tool(puma));
  p2 = makeposition("P2", t6, mnp_tool(puma), EQ, mnp_base_inv(puma), pw2, TL, mnp_tool(puma));
  m = makeposition("M", t6, mnp_tool(mbo), EQ, mnp_base_inv(mbo), mw, TL, mnp_tool(mbo));
  m2 = makeposition("M2", t6, mnp_tool(mbo), EQ, mnp_base_inv(mbo), mw2, TL, mnp_tool(mbo));

  mnp_setvel(puma, 50., 30.);
  mnp_setvel(mbo, 50., 30.);
  mnp_move(puma, p);
  mnp_move(mbo, m);
  waitfor(mnp_completed(puma) && mnp_completed(mbo));
  printf("1. both above the board\n");

  /* 2. The hand-off, in Cartesian mode. */
  mnp_setmod(puma, 'c');
  mnp_setmod(mbo, 'c');
  mnp_move(puma, p2);
  a = mnp_last_motion(puma);
  mnp_after(mbo, puma, a, RCCL_END);
  mnp_move(mbo, m2);
  b = mnp_last_motion(mbo);
  waitfor(mnp_ended(puma, a));
  order_ok = !mnp_started(mbo, b);
  waitfor(mnp_ended(mbo, b));
  printf("2. hand-off: microbo motion %d started after puma motion %d ended: %s\n", b, a,
         order_ok ? "yes" : "NO");

  /* 3. Back, starting and ending together: 10 mm for the PUMA, 60 mm for the Microbo. */
  rccl_together(1, puma, mbo, (MANIP*)0);
  mnp_move(puma, p);
  a = mnp_last_motion(puma);
  mnp_move(mbo, m);
  b = mnp_last_motion(mbo);
  waitfor(mnp_ended(puma, a) || mnp_ended(mbo, b));
  printf("3. together: puma ended %s, microbo ended %s in the same sample\n",
         mnp_ended(puma, a) ? "yes" : "no", mnp_ended(mbo, b) ? "yes" : "no");
  waitfor(mnp_completed(puma) && mnp_completed(mbo));

  return check(rcclRelease(0), "rcclRelease") != 0 || !order_ok;
}
