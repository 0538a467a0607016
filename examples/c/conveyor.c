/*
 * conveyor.c: tracking a conveyor through a functionally defined transform, in the manual's
 * style, on the simulated Microbo.
 *
 * CONV is the belt's displacement: its function, called once a sample, moves it along y at
 * SPEED mm/s from the moment the belt starts. The arm joins a part on the belt with a
 * Cartesian transition, rides along with it for two seconds, rises off it still following it,
 * and leaves for park in joint mode. Prints the largest
 * distance between the measured tool and the part while riding, and exits 1 above 3 mm.
 *
 *   cc conveyor.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 */
#include <stdio.h>
#include "rccl.h"
#include "rtc.h"

#define SPEED 40. /* mm/s */

long belt_start = -1; /* rtime when the belt started, ms */

int convfn(t) /* the belt: called every sample, as the manual's functions are */
TRSF_PTR t;
{
  if (belt_start < 0) belt_start = rtime;
  t->p.y = SPEED * (double)(rtime - belt_start) / 1000.;
  return 0;
}

int main()
{
  TRSF_PTR belt, conv, part, tool;
  POS_PTR ride, wait;
  TRSF now, goal;
  VECT d;
  double worst = 0.;
  long until;

  belt = gentr_rot("BELT", 300., -120., 230., xunit, 180.); /* the belt's start, z down */
  conv = newtrans("CONV", convfn);
  part = gentr_trsl("PART", 0., 0., 0.);
  tool = gentr_trsl("TOOL", 0., 0., 30.);
  ride = makeposition("RIDE", t6, tool, EQ, belt, conv, part, TL, tool);
  wait = makeposition("WAIT", t6, tool, EQ, belt, gentr_trsl("UP", 0., 0., -30.), TL, tool);
  if (ride == NULL || wait == NULL) return 1;

  if (rccl_open(0, 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  setvel(150, 90);
  move(park);
  move(wait);         /* in joint mode: over the belt's start */
  waitfor(wait->end);
  setmod('c');
  settime(100., 0.);  /* a 0.1 s transition onto the moving part */
  distance("dz", -30.);
  move(ride);         /* above the part, following it */
  move(ride);         /* down onto it */
  waitfor(ride->end);
  until = rtime + 2000;
  while (rtime < until) { /* ride along with it */
    Trsl(&goal, 0., SPEED * (double)(rtime - belt_start) / 1000., 0.); /* the belt now */
    trmult(&goal, belt, &goal);
    trmult(&goal, &goal, part);
    trmult(&now, t6, tool);
    vecsub(&d, &now.p, &goal.p);
    if (norm(&d) > worst) worst = norm(&d);
    if (rccl_wait_sample()) break;
  }
  printf("rode %.0f mm along the belt at %.0f mm/s; the tool was within %.2f mm of the part\n",
         conv->p.y, SPEED, worst);
  distance("dz", -40.);
  move(ride);         /* up off the part, still following it */
  setmod('j');
  move(park); /* off the belt, a transition out of the tracking (the belt carries the part
                 out of reach meanwhile) */
  waitfor(completed);
  if (rccl_close(0)) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  return worst < 3. ? 0 : 1;
}
