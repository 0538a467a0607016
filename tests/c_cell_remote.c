/*
 * A cell program in the manual's style, run twice by net_c_cell_test.cpp: with its robots in
 * this process (rccl_cell_open as always), and with RCCX_CELL_REMOTE=1 against two `rccx serve`
 * processes (the PUMA in one, the Microbo in the other). The program is the same; what it
 * prints must agree: the events in the same order, the times within a tolerance.
 *
 *   1. both arms above the board at once (joint mode);
 *   2. a hand-off in Cartesian mode: the Microbo starts once the PUMA's motion has ended;
 *   3. back, the PUMA first, then the Microbo after the PUMA's motion has started.
 *
 * With the argument "together", it also asks for a joint start (rccl_together) and prints the
 * answer: RTC_OK in one process, RTC_E_NOT_YET across processes. Lengths in mm, angles in
 * degrees; times (rtime) in ms. Written in the C of the time: it compiles with -std=gnu89.
 */
#include <stdio.h>
#include <string.h>

#include "rccl.h"
#include "rtc.h"

static int check(int code, const char* what) {
  printf("%s: %s\n", what, rtc_error_name(code));
  if (code != 0) fprintf(stderr, "%s: %s\n", what, rtc_error_message());
  return code;
}

/* rtime after one tick: the clock of the cell's first robot (simulated, or its serve's). */
static long now_ms(void) {
  rccl_wait_sample();
  return rtime;
}

int main(int argc, char** argv) {
  MANIP *puma, *mbo;
  TRSF_PTR pw, pw2, mw, mw2;
  POS_PTR p, p2, m, m2;
  int a, b, order_ok, started_first;
  long t0, t1;

  if (check(rccl_cell_open((char*)0), "open")) return 1;
  puma = rcclCreate("puma", 0);
  mbo = rcclCreate("microbo", 0);
  if (puma == 0 || mbo == 0 || check(rcclStart(), "start")) return 1;

  pw = gen_tr_rot("PW", -50., 0., 151.6, xunit, 180.);
  pw2 = gen_tr_rot("PW2", -50., 10., 151.6, xunit, 180.);
  mw = gen_tr_rot("MW", 100., 0., 151.6, xunit, 180.);
  mw2 = gen_tr_rot("MW2", 100., 60., 151.6, xunit, 180.);
  p = makeposition("P", t6, mnp_tool(puma), EQ, mnp_base_inv(puma), pw, TL, mnp_tool(puma));
  p2 = makeposition("P2", t6, mnp_tool(puma), EQ, mnp_base_inv(puma), pw2, TL, mnp_tool(puma));
  m = makeposition("M", t6, mnp_tool(mbo), EQ, mnp_base_inv(mbo), mw, TL, mnp_tool(mbo));
  m2 = makeposition("M2", t6, mnp_tool(mbo), EQ, mnp_base_inv(mbo), mw2, TL, mnp_tool(mbo));

  mnp_setvel(puma, 50., 30.);
  mnp_setvel(mbo, 50., 30.);
  t0 = now_ms();
  check(mnp_move(puma, p), "1. move puma P");
  check(mnp_move(mbo, m), "1. move microbo M");
  printf("1. motions %d %d; P end %d, M end %d\n", mnp_last_motion(puma), mnp_last_motion(mbo),
         p->end, m->end);
  waitfor(p->end && m->end);
  t1 = now_ms();
  printf("1. both above the board: P end %d code %d, M end %d code %d\n", p->end, p->code, m->end,
         m->code);
  printf("time 1: %ld ms\n", t1 - t0);

  mnp_setmod(puma, 'c');
  mnp_setmod(mbo, 'c');
  t0 = now_ms();
  check(mnp_move(puma, p2), "2. move puma P2");
  a = mnp_last_motion(puma);
  check(mnp_after(mbo, puma, a, RCCL_END), "2. microbo after puma's end");
  check(mnp_move(mbo, m2), "2. move microbo M2");
  b = mnp_last_motion(mbo);
  waitfor(mnp_ended(puma, a));
  order_ok = !mnp_started(mbo, b);
  waitfor(mnp_ended(mbo, b));
  t1 = now_ms();
  printf("2. hand-off: microbo motion %d started after puma motion %d ended: %s\n", b, a,
         order_ok ? "yes" : "NO");
  printf("time 2: %ld ms\n", t1 - t0);

  t0 = now_ms();
  check(mnp_move(puma, p), "3. move puma P");
  a = mnp_last_motion(puma);
  check(mnp_after(mbo, puma, a, RCCL_START), "3. microbo after puma's start");
  check(mnp_move(mbo, m), "3. move microbo M");
  b = mnp_last_motion(mbo);
  waitfor(mnp_started(mbo, b));
  started_first = mnp_started(puma, a);
  waitfor(mnp_completed(puma) && mnp_completed(mbo));
  t1 = now_ms();
  printf("3. back: puma motion %d had started when microbo motion %d started: %s\n", a, b,
         started_first ? "yes" : "NO");
  printf("3. completed %d; P end %d code %d, M end %d code %d\n", completed, p->end, p->code,
         m->end, m->code);
  printf("time 3: %ld ms\n", t1 - t0);

  if (argc > 1 && strcmp(argv[1], "together") == 0) {
    printf("together: %s\n", rtc_error_name(rccl_together(1, puma, mbo, (MANIP*)0)));
  }
  return check(rcclRelease(0), "release") != 0 || !order_ok || !started_first;
}
