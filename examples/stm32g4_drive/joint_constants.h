/* This joint's constants as the host tools write them (robot file, `jointguard identify`,
 * `jointguard calibrate`): the reference arm's joint 2 (models/ref3.yaml) at 1 kHz. A drive
 * maker generates this file per joint from their own robot file and JSON. */
#ifndef JOINT_CONSTANTS_H
#define JOINT_CONSTANTS_H
#define JOINT_NUMBER 2
#define JOINT_COUNT 3
#define SAMPLE_TIME_S 0.001
/* link: a_prev, alpha_prev, d, theta_offset [m, rad]; mass [kg]; com [m]; inertia [kg m^2] */
#define LINK_A_PREV 0.0
#define LINK_ALPHA_PREV -1.5707963267948966
#define LINK_D 0.0
#define LINK_MASS 4.0
#define LINK_COM_X 0.2
#define LINK_INERTIA_ZZ 0.08
#define LINK_ROTOR_INERTIA 0.05
#define LINK_TORQUE_CONSTANT 5.0
#define LINK_CURRENT_LIMIT 10.0
/* LuGre (identify JSON) and the band (calibrate JSON) */
#define LUGRE_SIGMA0 400.0
#define LUGRE_SIGMA1 3.0
#define LUGRE_SIGMA2 0.4
#define LUGRE_TAU_C 1.1
#define LUGRE_TAU_S 1.4
#define LUGRE_W_S 0.05
#define OBSERVER_GAIN 150.0
#define THRESHOLD_BASE 2.0
#define THRESHOLD_LOW_SPEED_EXTRA 3.0
#define THRESHOLD_LOW_SPEED_WIDTH 0.03
/* The holding detector (`jointguard calibrate --holding`: hold_change_threshold, and its
 * settle and reference times) and the dither deadband while holding (1-2 motor-encoder
 * counts per sample at the link side). */
#define HOLD_CHANGE_THRESHOLD 0.9
#define HOLD_SETTLE_S 0.15
#define HOLD_REFERENCE_S 0.016
#define HOLDING_VELOCITY_DEADBAND 0.005
#endif
