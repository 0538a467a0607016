/*
 * rtc_sine.c: an RTC program in the style of the 1983 real-time manual and the thesis (2.3,
 * 4.5.4.1). Joint 1 follows one period of a sine wave that starts at rest where the joint
 * stands, (1 - cos) / 2, out by AMPL and back: every sample fn2 sends the next point with
 * POSVEL (the joint is to be there one period later), and after NSAMPLES samples it sets
 * terminate, which ends control. fn1 watches how: the largest difference between where joint 1
 * was measured and where it was sent LAG samples before, and how far out it went.
 *
 * The control functions are written as in 1983 (K&R definitions, implicit int, no return
 * value): compiled as gnu89 with -Wno-implicit-int -Wno-return-type.
 *
 * Runs on the simulated Microbo (RCCX_ROBOT for another robot), in real time; with
 * RCCX_CLOCK=simulated time passes only in rtc_wait(), which is how main waits here.
 * Exit code 0 when control ended by the program's own terminate and the joint followed
 * within TOL; 1 otherwise; 2 when control could not start.
 */
#include <math.h>
#include <stdio.h>
#include "rtc.h"

#define JOINT 0      /* joint 1 */
#define AMPL 0.25    /* rad (a prismatic joint: mm) */
#define FREQ 0.5     /* Hz */
#define NSAMPLES 72  /* about 2 s at the Microbo's 28 ms */
#define LAG 2        /* a POSVEL sent by fn2 is reached at the end of the next sample */
#define TOL 0.03     /* rad: the Microbo's joint law lags about 0.02 rad on this wave */
#define PI 3.14159265358979

double center;           /* where joint 1 stood when control started */
double sent[NSAMPLES + 1];
double worst;            /* largest tracking difference seen by fn1 */
double peak;             /* farthest out measured */
long n;                  /* samples controlled */
char text[100];

fn1()
{
	double d;

	if (n >= LAG) {
		d = fabs(how.pos[JOINT] - sent[n - LAG]);
		if (d > worst)
			worst = d;
	}
	if (n > 0 && how.pos[JOINT] - center > peak)
		peak = how.pos[JOINT] - center;
}

fn2()
{
	if (n == 0)
		center = how.pos[JOINT];
	sent[n] = center + AMPL * (1. - cos(2. * PI * FREQ * (double)n * how.period_ms / 1000.)) / 2.;
	chg.i.motion[JOINT].set = POSVEL;
	chg.i.motion[JOINT].valir = sent[n];
	if (++n >= NSAMPLES) {
		sprintf(text, "sine done after %ld samples", n);
		rtc_message = text;
		terminate = 1;
	}
}

main()
{
	double ended_at;

	mess = "rtc_sine: channel closed";
	if (control(fn1, fn2) != RTC_OK) {
		print_rtc_error(rtc_error, 0);
		return 2;
	}
	while (rtc_wait(50.) == RTC_OK)
		;
	print_terminate_code();
	ended_at = how.pos[JOINT];
	release("rtc_sine: released");
	printf("joint 1 followed a %.2f rad sine wave for %ld samples of %.1f ms: out %.4f rad, "
	       "worst difference %.4f rad, ends %.4f rad from its start\n",
	       AMPL, n, how.period_ms, peak, worst, fabs(ended_at - center));
	if (terminate != RTC_TERM_USER_REQUEST || worst > TOL || peak < 0.9 * AMPL) {
		printf("rtc_sine: NOT as asked (terminate %ld)\n", terminate);
		return 1;
	}
	printf("rtc_sine: ok\n");
	return 0;
}
