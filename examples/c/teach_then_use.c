/*
 * teach_then_use.c: a grasp taught by hand with teach(), then used, in the manual's style, on
 * the simulated Microbo.
 *
 * teach(grasp, pos) first looks GRASP up in the position database (RCCX_DB, default rccx.db):
 * when it is there, it is used at once. Otherwise the teach loop runs on the terminal: move the
 * arm (`?` lists the commands), `e` records where it is, GRASP is solved so that the equation
 * T6 = OVER GRASP holds there, and stored. The program then leaves and comes back to the
 * taught place, and exits 1 if it comes back more than 2 mm off. With GRASP in no database
 * and nothing to teach it with (standard input at its end before `e`), it says how to run it
 * and exits 2.
 *
 *   cc teach_then_use.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 *   ./a.out < tests/c_teach_input.txt      (the teach commands from a file)
 */
#include <stdio.h>
#include "rccl.h"
#include "rtc.h"

int main()
{
  TRSF_PTR over, grasp;
  POS_PTR above, pos;
  TRSF taught;
  VECT d;

  over = gentr_rot("OVER", 300., 100., 260., xunit, 180.);
  grasp = newtrans("GRASP", hold);
  above = makeposition("ABOVE", t6, EQ, over, TL, t6);
  pos = makeposition("POS", t6, EQ, over, grasp, TL, t6);

  printf("GRASP comes from the position database (RCCX_DB, else ./rccx.db), else is taught\n"
         "on this terminal: move the arm (? lists the commands), then e records it.\n");
  if (rccl_open(0, 0) || rccl_control()) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  move(above);
  stop(500.); /* the wrist's joints settle a few hundred ms after the setpoint arrives */
  waitfor(completed);
  if (teach(grasp, pos) == NO) {
    fprintf(stderr, "teach_then_use: nothing taught (standard input ended before `e`)\n"
                    "usage: c_teach_then_use             (in a terminal: teach GRASP by hand)\n"
                    "       c_teach_then_use < COMMANDS  (teach commands from a file, e.g. "
                    "tests/c_teach_input.txt)\n"
                    "       RCCX_DB=FILE c_teach_then_use (GRASP saved there before)\n");
    rccl_close(0);
    return 2;
  }
  printr(grasp, stdout);
  trmult(&taught, over, grasp);
  move(park);
  move(pos);
  waitfor(pos->end);
  stop(300.);
  waitfor(completed);
  vecsub(&d, &t6->p, &taught.p);
  printf("back at the taught place, off by %.2f mm\n", norm(&d));
  move(park);
  waitfor(completed);
  if (rccl_close(0)) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  return norm(&d) < 2. ? 0 : 1;
}
