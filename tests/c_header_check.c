/* Compiled (not run) as gnu89, gnu99 and gnu11 with -Wall -Wextra -pedantic -Werror: the C
   headers and the manual's ways of writing calls, K&R definitions included. */
#include "rccl.h"
#include "rtc.h"

static int convfn(t) /* K&R, implicit int return in the manual's programs */
TRSF_PTR t;
{
  t->p.y += 0.5;
  return 0;
}

static void monitor(TRSF_PTR t) { /* a prototype-style function works as well */
  if (t->p.z < 0.) nextmove = YES;
}

int rccl_header_check(void);
int rccl_header_check(void) {
  TRSF_PTR trans, conv, mon, h, b;
  POS_PTR p;
  TRSF local;
  VECT v;
  trans = rot(newtrans("TRANS", const), zunit, 90.);
  conv = newtrans("CONV", convfn);
  mon = newtrans("MON", monitor);
  h = newtrans("H", hold);
  b = gen_tr_rot("B", 325.0, 150.0, 300.0, xunit, 180.);
  Trsl(&local, 1., 2., 3.);
  Trmult(&local, &local, trans);
  Cross(&v, &xunit, &yunit);
  h->p.z += 10.;
  p = makeposition("P", t6, EQ, b, conv, h, mon, TL, t6);
  distance("dz", -30.);
  setconf("lun");
  waitfor(p->end);
  stop(100.);
  return update(h, p) == 0 || teach(h, p) == YES;
}
