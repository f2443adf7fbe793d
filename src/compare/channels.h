/* Which channels of an image a comparison reads, and the rows every metric is reported in:
 * R, G, B, the three pooled (as OpenImageIO idiff) and Rec. 709 luminance Y. The bottom of
 * src/compare: every other comparison module (metrics, flip, structure, temporal, diffmap)
 * builds on it, and it includes none of them (docs/architecture.md, "Where a new metric goes"). */
#ifndef GR_CHANNELS_H
#define GR_CHANNELS_H

#include "image/image.h"

/* Rows of a comparison. GR_MCH_RGB pools the three channels' values (3 N samples): its MAE,
 * RMSE, PSNR (idiff peak) and max error are what `idiff` prints for an RGB image. */
typedef enum gr_metric_channel {
    GR_MCH_R = 0, GR_MCH_G, GR_MCH_B, GR_MCH_RGB, GR_MCH_Y, GR_MCH_COUNT
} gr_metric_channel;

/* Rec. 709 luminance weights (linear RGB). */
#define GR_LUM_R 0.2126
#define GR_LUM_G 0.7152
#define GR_LUM_B 0.0722

/* The channels compared in img: "R","G","B" by name; else the first three channels; a 1- or
 * 2-channel image is gray (channel 0 three times). */
void gr_metrics_pick_rgb(const gr_image *img, int rgb[3]);

/* Short name of a row: "R", "G", "B", "RGB", "Y". */
const char *gr_metric_channel_name(gr_metric_channel ch);

#endif
