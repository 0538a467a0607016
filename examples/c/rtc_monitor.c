/*
 * rtc_monitor.c: the thesis's RTC calls (2.3: rtc_open, rtc_control, rtc_release, rtc_close,
 * terminate, rtc_message, user_hangup, print_terminate_code), with a monitor in fn1.
 *
 * fn2 sends one joint (the first prismatic one, joint 2 of the Microbo; joint 1 on an arm
 * without one) toward a far target with POS at half its top speed. fn1 watches `how` every
 * sample: when the joint passes a fence short of the target, fn1 sends it back to where it was
 * when it crossed (POS again), says so in rtc_message, and ends control 10 samples later
 * through terminate. Ctrl-C runs the program's own hang-up function (user_hangup), which ends
 * control the same way.
 *
 * Written with prototypes (C89); main waits the thesis's way, testing terminate, and lets
 * time pass with rtc_wait() (which also serves RCCX_CLOCK=simulated). Exit code 0 when the
 * joint stopped past the fence and well short of the target, 1 otherwise, 2 when the session
 * could not open.
 */
#include <stdio.h>
#include "rtc.h"

static int j;             /* the joint moved (0-based) */
static const char *unit;  /* its unit: mm or rad */
static double start;      /* range values (rad or mm above the lower limit) */
static double fence;
static double target;
static double speed;      /* rad/s or mm/s */
static double stop_at;    /* where fn1 found the joint past the fence */
static long crossed;      /* the sample it did, 0 before */
static int sent;
static char text[120];

static void watch(void) /* fn1: after how is read, before the commands go out */
{
	if (crossed == 0 && how.pos[j] >= fence) {
		crossed = how.sample;
		stop_at = how.pos[j];
		chg.i.motion[j].set = POS;
		chg.i.motion[j].valir = stop_at;
		chg.i.motion[j].vel = speed;
		sprintf(text, "joint %d passed the fence at sample %ld (%.2f %s/s)", j + 1, crossed,
		        how.vel[j], unit);
		rtc_message = text;
	}
	if (crossed != 0 && how.sample >= crossed + 10)
		terminate = 1;
}

static void drive(void) /* fn2 */
{
	if (!sent) {
		chg.i.motion[j].set = POS;
		chg.i.motion[j].valir = target;
		chg.i.motion[j].vel = speed;
		sent = 1;
	}
}

static int hangup(void) /* Ctrl-C during control */
{
	terminate = 1;
	return 0;
}

int main(void)
{
	double end;

	if (rtc_open() != RTC_OK) {
		print_rtc_error(rtc_error, 0);
		return 2;
	}
	/* how holds the arm as rtc_open() read it, until control starts */
	for (j = 0; j < how.dof && how.type[j] != RTC_PRISMATIC; j++)
		;
	if (j == how.dof)
		j = 0;
	unit = how.type[j] == RTC_PRISMATIC ? "mm" : "rad";
	start = how.pos[j];
	fence = start + 0.3 * (how.range[j] - start);
	target = start + 0.8 * (how.range[j] - start);
	speed = 0.5 * how.vmax[j];
	printf("joint %d at %.3f %s of %.3f: to %.3f at %.3f %s/s, fence at %.3f\n", j + 1, start,
	       unit, how.range[j], target, speed, unit, fence);
	user_hangup = hangup;
	if (rtc_control(watch, drive) != RTC_OK) {
		print_rtc_error(rtc_error, 0);
		return 2;
	}
	while (!terminate)
		rtc_wait(10.);
	rtc_release(0);
	print_terminate_code();
	end = how.pos[j]; /* the last sample, now that control has ended */
	rtc_close(0);
	printf("stopped at %.3f %s: %.3f past the fence, %.3f short of the target\n", end, unit,
	       end - fence, target - end);
	if (terminate != RTC_TERM_USER_REQUEST || crossed == 0 || end < fence ||
	    end > fence + 0.25 * (target - fence)) {
		printf("rtc_monitor: NOT as asked\n");
		return 1;
	}
	printf("rtc_monitor: ok\n");
	return 0;
}
