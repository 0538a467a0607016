/*
 * varb_steps.c: a variable transform (varb) stepped by the program between motions, in the
 * manual's style (pumatask(), no main()). B is read at every sample: each change moves the goal
 * of P at once, and the move() that follows takes the tool there on a straight line from where
 * the arm stands. Four 20 mm steps down in Cartesian mode; each reached position is checked
 * against B (exit 1 beyond 1 mm).
 *
 *   cc varb_steps.c $(pkg-config --cflags --libs rccx-compat) && ./a.out
 */
#include <stdio.h>
#include <stdlib.h>
#include "rccl.h"
#include "manex.h"

pumatask()
{
	TRSF_PTR b, tool;
	POS_PTR p;
	TRSF now;
	VECT d;
	double worst = 0.;
	int i;

	b = newtrans("B", varb);
	tool = gentr_trsl("TOOL", 0., 0., 40.);
	Rot(b, xunit, 180.);
	b->p.x = 330.; b->p.y = 50.; b->p.z = 280.;
	p = makeposition("P", t6, tool, EQ, b, TL, tool);
	setvel(200, 100);
	move(p);
	waitfor(p->end);
	setmod('c');
	for (i = 0; i < 4; ++i) {
		b->p.z -= 20.;
		move(p);
		waitfor(p->end);
		waitfor(completed); /* the arm at rest: t6 measured there */
		trmult(&now, t6, tool);
		vecsub(&d, &now.p, &b->p);
		printf("step %d: tool at z = %.2f mm, B at %.2f mm\n", i + 1, now.p.z, b->p.z);
		if (norm(&d) > worst) worst = norm(&d);
	}
	printf("four steps of a varb followed; the tool within %.2f mm of B\n", worst);
	if (worst > 1.) exit(1);
}
