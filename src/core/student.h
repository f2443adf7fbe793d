/* Student's t quantiles for error bars estimated from a few batches: a standard error from
 * B batch means has B - 1 degrees of freedom, and (mean - truth) / stderr follows Student's t
 * with that many, not a normal law (with 8 batches |z| > 4 for 0.5 % of pixels, against
 * 6e-5 for a normal). Used wherever a significance or a --target-error decision is made. */
#ifndef GR_STUDENT_H
#define GR_STUDENT_H

#define GR_NORMAL_Q975 1.959963984540054 /* two-sided 95 % quantile of the standard normal */

/* The two-sided 95 % quantile t with P(|T| <= t) = 0.95 for `dof` degrees of freedom
 * (the 0.975 quantile); dof < 1 gives the normal's 1.96. Exact table to 30 degrees of
 * freedom, Cornish-Fisher expansion beyond (error below 1e-4). */
double gr_student_t975(int dof);

#endif
