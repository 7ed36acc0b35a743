/* The command line's progress line on stderr: one line rewritten with \r, naming
 * the stage, its share done, the time elapsed and the time left. Shown once the
 * command has run about a second when stderr is a terminal, from the start when
 * forced (--progress), never otherwise. A ticker thread redraws it, so the
 * elapsed time moves during stages that report no fraction (reading a file). */
#ifndef RASTRAY_TOOLS_PROGRESS_H
#define RASTRAY_TOOLS_PROGRESS_H

#include "rastray.h"

#include <stdbool.h>

/* Starts showing progress (forced: even when stderr is not a terminal, and at
 * once) and has dev report to it. Without a call nothing is ever shown. */
void progress_start(rr_device *dev, bool forced);
/* A stage of the command's own ("shading", "writing"): no fraction, elapsed time only. */
void progress_stage(const char *label);
/* The coming render passes are frame `frame` (0-based) of `frames` (--repeat): the
 * line shows the frames' fraction together and their time. */
void progress_frame(int frame, int frames);
/* Erases the line (on a terminal; elsewhere ends it with a newline) so that a
 * message can follow; the ticker draws it again while a stage runs. */
void progress_clear(void);
/* Erases the line and stops the ticker for good. */
void progress_stop(void);

#endif
