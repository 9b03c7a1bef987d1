/* What the example needs from the board, in SI units at the link side. Placeholders here
 * (board.c): a real drive reads its encoders and current ADC and commands its motor. */
#ifndef BOARD_H
#define BOARD_H
#include <stdbool.h>
#ifdef __cplusplus
extern "C" {
#endif
void board_init(void);                   /* clocks (PLL Q = 80 MHz for FDCAN), pins, ADC, encoders */
void board_wait_for_sample_tick(void);   /* the sample period's start (a timer flag) */
double board_link_position_rad(void);    /* link-side encoder */
double board_link_velocity_rad_s(void);  /* motor encoder differenced, / gear ratio */
double board_motor_torque_nm(void);      /* phase current x K_I at the link side */
bool board_holding_setpoint(void);       /* the position controller holds a constant setpoint */
void board_hold_position(void);          /* the reaction: stop and hold */
#ifdef __cplusplus
}
#endif
#endif
