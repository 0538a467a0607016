/* Control functions of compat_rtc_test.cpp, written in C as an RTC program of 1983 would
   (K&R definitions), run by the test through control() and rtc_control(). */
#include "rtc.h"

int ramp_joint;       /* 0-based */
double ramp_target;   /* range value, rad or mm */
double ramp_step;     /* per sample, rad or mm */
long ramp_samples;    /* samples fn2 ran */
long stop_after;      /* fn2 sets terminate after this many samples (0: never) */
double seen_first;    /* how.pos[ramp_joint] at the first fn1 */
long fn1_samples;     /* samples fn1 ran */
long fn1_last_sample; /* how.sample at the last fn1 */

int ramp_fn1()
{
	if (fn1_samples++ == 0)
		seen_first = how.pos[ramp_joint];
	fn1_last_sample = how.sample;
	return 0;
}

/* Steps the joint's POSVEL target toward ramp_target, ramp_step a sample. */
int ramp_fn2()
{
	double now;

	now = chg.i.motion[ramp_joint].valir;
	if (ramp_samples == 0)
		now = how.pos[ramp_joint];
	if (now < ramp_target - ramp_step)
		now += ramp_step;
	else if (now > ramp_target + ramp_step)
		now -= ramp_step;
	else
		now = ramp_target;
	chg.i.motion[ramp_joint].set = POSVEL;
	chg.i.motion[ramp_joint].valir = now;
	if (++ramp_samples == stop_after)
		terminate = 1;
	return 0;
}

/* One POS command to ramp_target at ramp_step per second. */
int pos_fn2()
{
	if (ramp_samples++ == 0) {
		chg.i.motion[ramp_joint].set = POS;
		chg.i.motion[ramp_joint].valir = ramp_target;
		chg.i.motion[ramp_joint].vel = ramp_step;
	}
	return 0;
}
