/* STAND-IN workload for testing the onboard platform layer (builds, emulators, heap guard, stack and
 * instruction measurement, cross-target comparison) before the real onboard core exists. To be replaced
 * by the core's C interface (include/ffsr/onboard/ffsr_onboard.h); nothing else should include this.
 *
 * Same shape as the core: an opaque handle whose memory is allocated once by init, an allocation-free
 * noexcept step per tick that fills a fixed-size C struct, and free. C99 and C++. */
#ifndef FFSR_ONBOARD_STANDIN_H
#define FFSR_ONBOARD_STANDIN_H

#ifdef __cplusplus
extern "C" {
/* The step's promise not to throw is part of its C++ declaration (and must match the definition). */
#define FFSR_STANDIN_NOEXCEPT noexcept
#else
#define FFSR_STANDIN_NOEXCEPT
#endif

#define FFSR_STANDIN_OUTPUTS 16

typedef struct ffsr_standin ffsr_standin;

typedef struct ffsr_standin_output {
  double values[FFSR_STANDIN_OUTPUTS];
} ffsr_standin_output;

/* Allocates and initialises; NULL on failure. */
ffsr_standin *ffsr_standin_init(void);

/* One tick; 0 on success. Allocation-free. */
int ffsr_standin_step(ffsr_standin *handle, ffsr_standin_output *output) FFSR_STANDIN_NOEXCEPT;

void ffsr_standin_free(ffsr_standin *handle);

#ifdef __cplusplus
}
#endif

#endif
