/*
 * A collision stop in a cell reaches the C program as it would for one robot: the stopped
 * motions' POS.code is RTC_E_MOTION, and motions that then move the arms apart run to their
 * end (POS.code 0) without another stop. Both arms are sent to the same point over the board.
 * Exit 0 when all of that holds.
 */
#include <stdio.h>

#include "rccl.h"
#include "rtc.h"

int main(void) {
  MANIP *puma, *mbo;
  TRSF_PTR meet, pw, mw;
  POS_PTR p_meet, m_meet, p_back, m_back;
  int bad = 0, code;

  if (rccl_cell_open((char*)0) != 0) return 1;
  puma = rcclCreate("puma", 0);
  mbo = rcclCreate("microbo", 0);
  if (puma == 0 || mbo == 0 || rcclStart() != 0) return 1;

  meet = gen_tr_rot("MEET", 0., 0., 160., xunit, 180.);
  pw = gen_tr_rot("PW", -120., 0., 180., xunit, 180.);
  mw = gen_tr_rot("MW", 140., 0., 180., xunit, 180.);
  p_meet =
      makeposition("P_MEET", t6, mnp_tool(puma), EQ, mnp_base_inv(puma), meet, TL, mnp_tool(puma));
  m_meet =
      makeposition("M_MEET", t6, mnp_tool(mbo), EQ, mnp_base_inv(mbo), meet, TL, mnp_tool(mbo));
  p_back =
      makeposition("P_BACK", t6, mnp_tool(puma), EQ, mnp_base_inv(puma), pw, TL, mnp_tool(puma));
  m_back = makeposition("M_BACK", t6, mnp_tool(mbo), EQ, mnp_base_inv(mbo), mw, TL, mnp_tool(mbo));

  mnp_setvel(puma, 100., 60.);
  mnp_setvel(mbo, 100., 60.);
  mnp_move(puma, p_meet);
  mnp_move(mbo, m_meet);
  waitfor(mnp_completed(puma) && mnp_completed(mbo));
  printf("meeting: puma POS.code %d, microbo POS.code %d (RTC_E_MOTION is %d)\n", p_meet->code,
         m_meet->code, RTC_E_MOTION);
  if (p_meet->code != RTC_E_MOTION && m_meet->code != RTC_E_MOTION) {
    printf("FAIL: no stopped motion set POS.code\n");
    bad = 1;
  }

  /* Apart again, from where they stopped: each back to its own side. */
  mnp_setvel(puma, 30., 30.);
  mnp_setvel(mbo, 30., 30.);
  mnp_move(puma, p_back);
  mnp_move(mbo, m_back);
  waitfor(mnp_completed(puma) && mnp_completed(mbo));
  printf("apart: puma POS.code %d, microbo POS.code %d\n", p_back->code, m_back->code);
  if (p_back->code != 0 || m_back->code != 0) {
    printf("FAIL: moving apart was stopped\n");
    bad = 1;
  }

  code = rcclRelease(0);
  printf("rcclRelease: %s (RTC_E_MOTION: the meeting motions failed)\n", rtc_error_name(code));
  if (code != RTC_E_MOTION) bad = 1;
  return bad;
}
