/*
 * guarded.c: a guarded approach with a monitor and nextmove, in the manual's style, on the
 * simulated Microbo.
 *
 * The arm goes down, slowly, towards a goal 60 mm below a surface it does not know exactly.
 * MON is a functionally defined transform (the identity) whose function is a monitor: every
 * sample it looks at the measured T6 and, when the tool reaches the surface (a stand-in for a
 * touch sensor), sets nextmove: the motion down ends where the arm is and the next one, the
 * retreat, starts. Prints where the surface was found and exits 1 if not within 3 mm of it.
 *
 *   cc guarded.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 */
#include <stdio.h>
#include "rccl.h"
#include "rtc.h"

#define SURFACE_Z 232. /* mm, in the base frame: what the sensor would find */

int touched = NO;
double touched_z = 0.;

int monitor(t) /* called every sample while the motion that uses MON runs */
TRSF_PTR t;
{
  (void)t;
  if (!touched && t6->p.z <= SURFACE_Z) {
    touched = YES;
    touched_z = t6->p.z;
    nextmove = YES;
  }
  return 0;
}

int main()
{
  TRSF_PTR over, down, mon;
  POS_PTR above, search;

  over = gentr_rot("OVER", 300., 60., 260., xunit, 180.); /* z down */
  down = gentr_trsl("DOWN", 0., 0., 60.);
  mon = newtrans("MON", monitor);
  above = makeposition("ABOVE", t6, EQ, over, TL, t6);
  search = makeposition("SEARCH", t6, EQ, over, down, mon, TL, t6);

  if (rccl_open(0, 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  move(above);
  waitfor(above->end);
  setmod('c');
  setvel(15., 30.);
  move(search); /* guarded: ends at the touch */
  move(above);  /* the retreat */
  waitfor(search->end);
  if (search->code == RCCL_NEXTMOVE)
    printf("touched at z = %.2f mm (surface at %.0f mm), stopped at z = %.2f mm\n", touched_z,
           SURFACE_Z, t6->p.z);
  else
    printf("no touch: the search went to its end\n");
  waitfor(completed);
  setmod('j');
  move(park);
  waitfor(completed);
  if (rccl_close(0)) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  return touched && touched_z > SURFACE_Z - 3. && touched_z <= SURFACE_Z ? 0 : 1;
}
