/* Channel choice and row names of a comparison (channels.h). */
#include "compare/channels.h"

const char *gr_metric_channel_name(gr_metric_channel ch)
{
    switch (ch) {
    case GR_MCH_R: return "R";
    case GR_MCH_G: return "G";
    case GR_MCH_B: return "B";
    case GR_MCH_RGB: return "RGB";
    case GR_MCH_Y: return "Y";
    case GR_MCH_COUNT: break;
    }
    return "?";
}

void gr_metrics_pick_rgb(const gr_image *img, int rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0;
    if (!img) return;
    int r = gr_image_channel(img, "R"), g = gr_image_channel(img, "G"), b = gr_image_channel(img, "B");
    if (r >= 0 && g >= 0 && b >= 0) {
        rgb[0] = r, rgb[1] = g, rgb[2] = b;
    } else if (img->nchannels >= 3) {
        rgb[0] = 0, rgb[1] = 1, rgb[2] = 2;
    }
}
