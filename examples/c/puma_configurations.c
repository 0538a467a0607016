/*
 * puma_configurations.c: one goal reached in four arm configurations on the simulated PUMA
 * 560, with setconf (l/r shoulder, u/d elbow, n/f wrist), in the manual's style.
 *
 * Joint moves may change configuration; Cartesian ones cannot: a Cartesian move() to a goal
 * the present configuration does not reach is refused at the call. Prints the error at the
 * goal in each configuration, measured, and exits 1 if one is 2 mm or more.
 *
 *   cc puma_configurations.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 */
#include <stdio.h>
#include "rccl.h"
#include "rtc.h"

int main()
{
  static char* confs[] = {"lun", "rdn", "lefty down flip", "righty up"};
  TRSF_PTR g, up;
  POS_PTR goal, above;
  VECT d;
  int i, bad = 0;

  /* p (mm), approach vector, orientation vector: a pose all eight configurations reach */
  g = gentr_pao("G", 400., -200., 300., 0., -1., 0., -1., 0., 0.);
  up = gentr_trsl("UP", 0., 0., -50.);
  goal = makeposition("GOAL", t6, EQ, g, TL, t6);
  above = makeposition("ABOVE", t6, EQ, g, up, TL, t6);

  if (rccl_open("puma560", 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  setvel(200., 90.);
  for (i = 0; i < 4; i++) {
    setmod('j');
    setconf(confs[i]);
    move(goal);
    waitfor(goal->end);
    stop(200.);
    waitfor(completed);
    vecsub(&d, &t6->p, &g->p);
    printf("%-16s error %.2f mm\n", confs[i], norm(&d));
    if (norm(&d) >= 2.) bad = 1;
    setmod('c');       /* a Cartesian move stays in the configuration */
    setconf("");
    move(above);
    move(goal);
    waitfor(goal->end);
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
