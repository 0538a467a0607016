/* rccx: the window washer program of the thesis (section 2.4.3), as it was printed there,
   compiled as C over rccx's compatibility layer (compat/rccl.h, compat/rtc.h) and run on the
   simulated Microbo (RCCX_ROBOT chooses another robot, RCCX_LOG=FILE logs every sample).
   The three printed fragments are joined; the only changes are marked "rccx:". */

/*
    washer.c,    the window washer program.
                robot moves, with gradually increasing
                translational and rotational velocity,
                through 4 points arranged in a rectangle
                in the yz plane. The tool tip is maintained
                orthogonal to the plane.
*/

#include "rccl.h"    /* the basic rccl include file */
#include "rtc.h"     /* the basic rtc include file */
#include <stdio.h>   /* rccx: printf; 1986 compilers did not ask for it */
#include <stdlib.h>  /* rccx: exit */

int main(void) /* rccx: ANSI C; was "main()" */
{
    TRSF_PTR b, c, d, e;
    POS_PTR  p1, p2, p3, p4;
    int      tvel = 100;
    int      rvel = 100;
    int      i;

    /*-- translations from robot origin to 4 corners ---*/
    /*-- rotation so tool pointing towards table ---*/

b = gen_tr_rot("B", 325.0, 150.0, 300.0, xunit, 180.);
c = gen_tr_rot("C", 325.0, -150.0, 300.0, xunit, 180.);
d = gen_tr_rot("D", 325.0, -150.0, 250.0, xunit, 180.);
e = gen_tr_rot("E", 325.0, 150.0, 250.0, xunit, 180.);

    /*-- corresponding position equations --*/
p1 = makeposition("P1", t6, EQ, b, TL, t6);
p2 = makeposition("P2", t6, EQ, c, TL, t6);
p3 = makeposition("P3", t6, EQ, d, TL, t6);
p4 = makeposition("P4", t6, EQ, e, TL, t6);

if (rccl_open (0, 0)) /*-- start the RCCL control session --*/
{ print_rtc_error(rtc_error, 0);
  exit(-1);
}
if (rccl_control ()) /*-- start the trajectory generator --*/
{ print_rtc_error(rtc_error, 0);
  exit(-1);
}

setvel(tvel, rvel); /*-- set trans, rot velocities --*/

move(park); /*-- move to the park position --*/
waitfor (park->end); /*-- and stop there --*/
move(p1); /*-- move to p1 --*/
waitfor(p1->end); /*-- and stop there --*/

setmod('c'); /*-- cartesian mode --*/
for (i=0; i<3; i++)
{ printf("velocity %d, %d\n", tvel, rvel);
  move(p2); /*-- move to p2 --*/
  move(p3); /*-- move to p3 --*/
  move(p4); /*-- move to p4 --*/
  move(p1); /*-- move to p1 --*/
  tvel += 5;
  rvel += 10; /*-- faster... --*/
  setvel(tvel, rvel);
}

waitfor (completed); /*-- wait for queue to empty --*/

setmod('j'); /*-- back to joint mode --*/
move(park); /*-- move to the park position --*/
waitfor (park->end); /*-- wait till done --*/

    if (rccl_close (0))      /*-- terminate control session ---*/
    { print_rtc_error(rtc_error, 0);
      exit(-1);
    }
}
