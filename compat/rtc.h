/*
 * rtc.h: the 1986 RTC names a C program of the thesis uses (section 2.3): the error variable
 * `rtc_error` and `print_rtc_error()`. Part of rccx's C compatibility layer (library
 * rccx_compat, see rccl.h for the motion calls); the real-time layer underneath is rccx::rtc.
 *
 * Every call of rccl.h that fails sets `rtc_error` to one of the codes below and keeps a
 * message saying what went wrong and what to do (rtc_error_message()). Codes are never reset
 * by a call that succeeds: test the call's result, then read `rtc_error`.
 *
 * The planning level is one thread: call these functions from one thread only.
 */
#ifndef RCCX_COMPAT_RTC_H
#define RCCX_COMPAT_RTC_H

#ifdef __cplusplus
extern "C" {
#endif

/* The values of rtc_error. */
#define RTC_OK 0            /* no error */
#define RTC_E_SEQUENCE 1    /* a call out of order: move() before rccl_control(), two opens */
#define RTC_E_ROBOT 2       /* no such robot (RCCX_ROBOT), or it cannot be simulated */
#define RTC_E_OPEN 3        /* the session cannot open: a bad period, RCCX_LOG not writable */
#define RTC_E_ARGUMENT 4    /* a bad argument: a null or unknown pointer, a speed <= 0, ... */
#define RTC_E_EQUATION 5    /* a malformed position equation (makeposition) */
#define RTC_E_UNREACHABLE 6 /* a motion not queued: goal out of reach or limits, queue full */
#define RTC_E_MOTION 7      /* a queued motion failed (or was cancelled) while running */
#define RTC_E_TERMINATED 8  /* control ended by itself: a limit, a fault, Ctrl-C */
#define RTC_E_INTERNAL 9    /* an unexpected failure inside rccx (the message says which) */
#define RTC_E_NOT_YET 10    /* a call rccx declares but does not do yet (comply, lock) */

/** The code of the last error (RTC_OK until one happens). */
extern int rtc_error;

/**
 * Prints the meaning of error `code` on stdout, as the 1986 RTC did; when `code` is the
 * present rtc_error, also the message of that error (what failed, why, what to do).
 * `flags`: reserved, pass 0 (the thesis's programs all do).
 */
void print_rtc_error(int code, int flags);

/** The message of the last error ("" when there was none). Valid until the next call. */
const char* rtc_error_message(void);

/** The name of an error code ("RTC_E_EQUATION"), or "unknown". */
const char* rtc_error_name(int code);

#ifdef __cplusplus
}
#endif

#endif /* RCCX_COMPAT_RTC_H */
