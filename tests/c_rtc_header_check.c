/* Compiled (not run) as gnu89, gnu99 and gnu11 with -Wall -Wextra -pedantic -Werror: rtc.h
   alone and the ways the 1983 manual and the thesis write RTC programs, K&R definitions
   included (tests/CMakeLists.txt). */
#include <stddef.h>
#include <stdio.h>
#include "rtc.h"

static int j;
static char text[64];

static int fn1() /* K&R, int: the functions of 1983 */
{
	if (how.pos[j] > how.range[j] - 1. || (how.flags[j] & RTC_F_OBS_POS_OUT))
		terminate = 1;
	return 0;
}

static void fn2(void) /* a prototype works as well */
{
	chg.i.motion[j].set = POSVEL;
	chg.i.motion[j].valir = how.pos[j] + 0.001;
	chg.i.motion[1].set = POS;
	chg.i.motion[1].valir = 10.;
	chg.i.motion[1].vel = 5.;
	chg.i.motion[2].set = STOPCAL;
	chg.hand = RTC_HAND_CLOSE;
	chg.checking = RTC_CHECK_ALL & ~RTC_CHECK_OBS_VEL;
	sprintf(text, "sample %ld", how.sample);
	rtc_message = text;
}

static int hangup()
{
	terminate = 1;
	return 0;
}

int rtc_header_check(void);
int rtc_header_check(void)
{
	mess = "closed";
	user_hangup = hangup;
	if (rtc_open() != RTC_OK || rtc_control(fn1, fn2) != RTC_OK)
		print_rtc_error(rtc_error, 0);
	while (!terminate)
		rtc_wait(10.);
	print_terminate_code();
	rtc_release(0);
	rtc_close(1);
	control(NULL, fn2);
	control(fn1, 0);
	(void)rtc_wait_terminated(-1.);
	return release("done") + (rtc_terminate_name(terminate)[0] == 'u');
}
