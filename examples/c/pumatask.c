/*
 * pumatask.c: a program as the RCCL user's manual prints them: rccl.h and manex.h, the task in
 * pumatask() and no main() (rccx_compat's main() opens the session, calls it, and waits for
 * its motions), K&R C with implicit int. The tool, 50 mm along the hand's z axis, draws a
 * 100 mm square on a table in Cartesian mode; afterwards the program checks where the arm
 * stands against the square's last corner and exits 1 when it is more than 1 mm off.
 *
 *   cc pumatask.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 */
#include <stdio.h>
#include <stdlib.h>
#include "rccl.h"
#include "manex.h"

#define SIDE 100. /* mm */

pumatask()
{
	TRSF_PTR table, corner, tool;
	POS_PTR  p;
	TRSF     reached, want;
	VECT     d;
	int      i;

	table = gentr_rot("TABLE", 320., -50., 220., xunit, 180.); /* z down onto the table */
	corner = newtrans("CORNER", hold);
	tool = gentr_trsl("TOOL", 0., 0., 50.);
	Ident(corner);
	p = makeposition("P", t6, tool, EQ, table, corner, TL, tool);

	setvel(100, 50);
	move(park);
	move(p);                 /* joint mode: onto the first corner */
	setmod('c');
	for (i = 1; i <= 4; ++i) { /* the other corners, the last back at the first */
		waitfor(p->end);
		Trsl(corner, (i == 1 || i == 2) ? SIDE : 0., (i == 2 || i == 3) ? SIDE : 0., 0.);
		move(p);
	}
	waitfor(completed);

	trmult(&reached, t6, tool);
	trmult(&want, table, corner);
	vecsub(&d, &reached.p, &want.p);
	printf("square drawn; the tool ended %.3f mm from its last corner\n", norm(&d));
	if (norm(&d) > 1.) exit(1);
}
