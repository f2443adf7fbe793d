/* The interactive comparison block of index.html: see viewer.h; docs/report.md. */
#include "report/viewer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "compare/metrics.h"
#include "image/oiio.h"

/* The page's script, one line per string (vanilla JavaScript, no external resource). It reads
 * window.GRV_DATA {w, h, step, exposure, truth, tech: [{name, scale, img, flip, flipMean}]}. */
static const char *const JS[] = {
    "(function () {\n",
    "'use strict';\n",
    "var D = window.GRV_DATA, root = document.getElementById('grv');\n",
    "var cv = document.getElementById('grv-canvas'), cx = cv.getContext('2d');\n",
    "var sel = document.getElementById('grv-tech'), wipe = document.getElementById('grv-wipe');\n",
    "var ev = document.getElementById('grv-ev'), evv = document.getElementById('grv-evv');\n",
    "var label = document.getElementById('grv-label'), px = document.getElementById('grv-px');\n",
    "var W = D.w, H = D.h, N = W * H;\n",
    "var off = document.createElement('canvas');\n",
    "off.width = W; off.height = H;\n",
    "var ox = off.getContext('2d'), buf = ox.createImageData(W, H);\n",
    "var S = {tech: 0, mode: 'flip', showTest: false, zoom: 1, px: 0, py: 0, fit: cv.width / W};\n",
    "var truth = null, tests = [], flips = [], pending = 1 + D.tech.length;\n",
    "D.tech.forEach(function (t) { if (t.flip) pending++; });\n",
    "var lut = new Uint8ClampedArray(4097);\n",
    "for (var i = 0; i <= 4096; i++) {\n",
    "  var x = i / 4096;\n",
    "  lut[i] = Math.round(255 * (x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055));\n",
    "}\n",
    "/* RGBE in an RGB PNG twice as tall: mantissas above, exponent below (docs/report.md). */\n",
    "function decode(url, done) {\n",
    "  var im = new Image();\n",
    "  im.onload = function () {\n",
    "    var c = document.createElement('canvas');\n",
    "    c.width = W; c.height = 2 * H;\n",
    "    var g = c.getContext('2d', {willReadFrequently: true});\n",
    "    g.drawImage(im, 0, 0);\n",
    "    var d = g.getImageData(0, 0, W, 2 * H).data, f = new Float32Array(3 * N);\n",
    "    for (var p = 0; p < N; p++) {\n",
    "      var e = d[4 * (N + p)];\n",
    "      if (e === 0) continue;\n",
    "      var s = Math.pow(2, e - 136);\n",
    "      f[3 * p] = (d[4 * p] + 0.5) * s;\n",
    "      f[3 * p + 1] = (d[4 * p + 1] + 0.5) * s;\n",
    "      f[3 * p + 2] = (d[4 * p + 2] + 0.5) * s;\n",
    "    }\n",
    "    done(f);\n",
    "  };\n",
    "  im.src = url;\n",
    "}\n",
    "function image(url, done) {\n",
    "  var im = new Image();\n",
    "  im.onload = function () { done(im); };\n",
    "  im.src = url;\n",
    "}\n",
    "function loaded() {\n",
    "  if (--pending > 0) return;\n",
    "  root.setAttribute('data-ready', '1');\n",
    "  draw();\n",
    "}\n",
    "decode(D.truth, function (f) { truth = f; loaded(); });\n",
    "D.tech.forEach(function (t, k) {\n",
    "  decode(t.img, function (f) { tests[k] = f; loaded(); });\n",
    "  if (t.flip) image(t.flip, function (im) { flips[k] = im; loaded(); });\n",
    "});\n",
    "function tone(f, gain, x0, x1) {\n",
    "  var o = buf.data;\n",
    "  for (var y = 0; y < H; y++) {\n",
    "    for (var x = x0; x < x1; x++) {\n",
    "      var p = y * W + x;\n",
    "      for (var c = 0; c < 3; c++) {\n",
    "        var v = f[3 * p + c] * gain;\n",
    "        o[4 * p + c] = lut[v >= 1 ? 4096 : v > 0 ? Math.round(v * 4096) : 0];\n",
    "      }\n",
    "      o[4 * p + 3] = 255;\n",
    "    }\n",
    "  }\n",
    "}\n",
    "function wipeX() { return Math.round(W * wipe.value / 1000); }\n",
    "function draw() {\n",
    "  if (pending > 0) return;\n",
    "  var t = D.tech[S.tech], g = D.exposure * Math.pow(2, ev.value / 10);\n",
    "  var text;\n",
    "  if (S.mode === 'flipmap') {\n",
    "    if (flips[S.tech]) {\n",
    "      ox.drawImage(flips[S.tech], 0, 0);\n",
    "      text = 'HDR-FLIP map of ' + t.name + ' x a (mean ' + t.flipMean.toPrecision(3) + '; magma: black 0, yellow 1)';\n",
    "    } else {\n",
    "      ox.fillStyle = '#000';\n",
    "      ox.fillRect(0, 0, W, H);\n",
    "      text = 'no FLIP map for ' + t.name;\n",
    "    }\n",
    "  } else {\n",
    "    if (S.mode === 'wipe') {\n",
    "      var xw = wipeX();\n",
    "      tone(truth, g, 0, xw);\n",
    "      tone(tests[S.tech], g * t.scale, xw, W);\n",
    "      text = 'wipe: ground truth | ' + t.name + ' x ' + t.scale.toPrecision(4);\n",
    "    } else if (S.showTest) {\n",
    "      tone(tests[S.tech], g * t.scale, 0, W);\n",
    "      text = 'showing ' + t.name + ' x ' + t.scale.toPrecision(4) + ' (click or space: flip)';\n",
    "    } else {\n",
    "      tone(truth, g, 0, W);\n",
    "      text = 'showing the ground truth (click or space: flip to ' + t.name + ')';\n",
    "    }\n",
    "    ox.putImageData(buf, 0, 0);\n",
    "  }\n",
    "  cx.setTransform(1, 0, 0, 1, 0, 0);\n",
    "  cx.fillStyle = '#000';\n",
    "  cx.fillRect(0, 0, cv.width, cv.height);\n",
    "  var s = S.fit * S.zoom;\n",
    "  cx.setTransform(s, 0, 0, s, S.px, S.py);\n",
    "  cx.imageSmoothingEnabled = false;\n",
    "  cx.drawImage(off, 0, 0);\n",
    "  if (S.mode === 'wipe') {\n",
    "    cx.setTransform(1, 0, 0, 1, 0, 0);\n",
    "    var sx = S.px + s * wipeX();\n",
    "    cx.fillStyle = '#fff';\n",
    "    cx.fillRect(Math.round(sx) - 1, 0, 2, cv.height);\n",
    "  }\n",
    "  label.textContent = text + '; zoom ' + S.zoom.toPrecision(3) + 'x';\n",
    "  evv.textContent = (ev.value >= 0 ? '+' : '') + (ev.value / 10).toFixed(1) + ' EV';\n",
    "  root.setAttribute('data-state', S.mode + (S.mode === 'flip' ? (S.showTest ? ':test' : ':truth') : '') +\n",
    "                    ':' + S.tech);\n",
    "}\n",
    "function setMode(m) {\n",
    "  S.mode = m;\n",
    "  var r = root.querySelectorAll('input[name=grv-mode]');\n",
    "  for (var i = 0; i < r.length; i++) r[i].checked = r[i].value === m;\n",
    "  draw();\n",
    "}\n",
    "function flip() {\n",
    "  if (S.mode !== 'flip') S.mode = 'flip', S.showTest = false;\n",
    "  S.showTest = !S.showTest;\n",
    "  setMode('flip');\n",
    "}\n",
    "function zoomAt(f, sx, sy) {\n",
    "  var z = Math.min(64, Math.max(1, S.zoom * f));\n",
    "  f = z / S.zoom;\n",
    "  S.px = sx - (sx - S.px) * f;\n",
    "  S.py = sy - (sy - S.py) * f;\n",
    "  S.zoom = z;\n",
    "  if (z === 1) S.px = S.py = 0;\n",
    "  draw();\n",
    "}\n",
    "function canvasXY(e) {\n",
    "  var r = cv.getBoundingClientRect();\n",
    "  return [(e.clientX - r.left) * cv.width / r.width, (e.clientY - r.top) * cv.height / r.height];\n",
    "}\n",
    "var drag = null;\n",
    "cv.addEventListener('mousedown', function (e) {\n",
    "  var p = canvasXY(e);\n",
    "  drag = {x: p[0], y: p[1], px: S.px, py: S.py, moved: false};\n",
    "  cv.focus();\n",
    "  e.preventDefault();\n",
    "});\n",
    "window.addEventListener('mousemove', function (e) {\n",
    "  var p = canvasXY(e);\n",
    "  if (drag) {\n",
    "    var dx = p[0] - drag.x, dy = p[1] - drag.y;\n",
    "    if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;\n",
    "    if (drag.moved) { S.px = drag.px + dx; S.py = drag.py + dy; draw(); }\n",
    "    return;\n",
    "  }\n",
    "  var s = S.fit * S.zoom, ix = Math.floor((p[0] - S.px) / s), iy = Math.floor((p[1] - S.py) / s);\n",
    "  if (e.target !== cv || pending > 0 || ix < 0 || iy < 0 || ix >= W || iy >= H) return;\n",
    "  var q = 3 * (iy * W + ix), t = tests[S.tech], a = D.tech[S.tech].scale;\n",
    "  px.textContent = 'pixel (' + ix * D.step + ', ' + iy * D.step + '): truth ' +\n",
    "    [truth[q], truth[q + 1], truth[q + 2]].map(function (v) { return v.toPrecision(3); }).join(' ') +\n",
    "    '; ' + D.tech[S.tech].name + ' x a ' +\n",
    "    [t[q] * a, t[q + 1] * a, t[q + 2] * a].map(function (v) { return v.toPrecision(3); }).join(' ');\n",
    "});\n",
    "window.addEventListener('mouseup', function (e) {\n",
    "  if (!drag) return;\n",
    "  var moved = drag.moved;\n",
    "  drag = null;\n",
    "  if (moved || pending > 0) return;\n",
    "  if (S.mode === 'wipe') {\n",
    "    var p = canvasXY(e), s = S.fit * S.zoom;\n",
    "    wipe.value = Math.round(1000 * Math.min(1, Math.max(0, (p[0] - S.px) / s / W)));\n",
    "    draw();\n",
    "  } else flip();\n",
    "});\n",
    "cv.addEventListener('wheel', function (e) {\n",
    "  var p = canvasXY(e);\n",
    "  zoomAt(e.deltaY < 0 ? 1.25 : 0.8, p[0], p[1]);\n",
    "  e.preventDefault();\n",
    "}, {passive: false});\n",
    "root.addEventListener('keydown', function (e) {\n",
    "  var k = e.key;\n",
    "  if (e.target === sel || e.target === ev || e.target === wipe) {\n",
    "    if (k !== ' ' && k !== 'f') return;\n",
    "  }\n",
    "  if (k === ' ' || k === 'f') flip();\n",
    "  else if (k === 'w') setMode('wipe');\n",
    "  else if (k === 'm') setMode('flipmap');\n",
    "  else if (k === '+' || k === '=') zoomAt(1.25, cv.width / 2, cv.height / 2);\n",
    "  else if (k === '-') zoomAt(0.8, cv.width / 2, cv.height / 2);\n",
    "  else if (k === '0') { S.zoom = 1; S.px = S.py = 0; draw(); }\n",
    "  else if (k === '[' || k === ']') { ev.value = +ev.value + (k === ']' ? 5 : -5); draw(); }\n",
    "  else if (k >= '1' && k <= '9' && +k <= D.tech.length) { S.tech = +k - 1; sel.value = String(S.tech); draw(); }\n",
    "  else return;\n",
    "  e.preventDefault();\n",
    "});\n",
    "sel.addEventListener('change', function () { S.tech = +sel.value; draw(); });\n",
    "wipe.addEventListener('input', function () { setMode('wipe'); });\n",
    "ev.addEventListener('input', draw);\n",
    "root.querySelectorAll('input[name=grv-mode]').forEach(function (r) {\n",
    "  r.addEventListener('change', function () { if (r.checked) setMode(r.value); });\n",
    "});\n",
    "document.getElementById('grv-reset').addEventListener('click', function () {\n",
    "  S.zoom = 1; S.px = S.py = 0; ev.value = 0; draw();\n",
    "});\n",
    "window.grViewer = {state: S, draw: draw, pixel: function (which, x, y) {\n",
    "  var f = which === 'truth' ? truth : tests[which], q = 3 * (y * W + x);\n",
    "  return [f[q], f[q + 1], f[q + 2]];\n",
    "}};\n",
    "})();\n",
};

static const char *const CSS =
    "#grv .vctl{margin:.4em 0;display:flex;flex-wrap:wrap;gap:.4em 1.2em;align-items:center}"
    "#grv canvas{background:#000;cursor:crosshair;display:block;max-width:100%;border:1px solid #444}"
    "#grv canvas:focus{outline:2px solid #58a}#grv .mono{font-family:monospace;font-size:90%}";

void gr_viewer_rgbe(float r, float g, float b, unsigned char out[4])
{
    /* Ward's RGBE (Graphics Gems II, "Real pixels"): one exponent shared by the three
     * channels, 8-bit mantissas relative to the largest; negative values are clamped to 0. */
    r = r > 0 ? r : 0;
    g = g > 0 ? g : 0;
    b = b > 0 ? b : 0;
    float m = r > g ? r : g;
    if (b > m) m = b;
    int e = 0;
    if (!(m >= 1e-32f)) {
        out[0] = out[1] = out[2] = out[3] = 0;
        return;
    }
    const double v = frexp((double)m, &e) * 256.0 / (double)m; /* m * v in [128, 256) */
    if (e + 128 > 255) { /* beyond ~1e38: saturate */
        out[0] = out[1] = out[2] = 255;
        out[3] = 255;
        return;
    }
    if (e + 128 < 1) {
        out[0] = out[1] = out[2] = out[3] = 0;
        return;
    }
    const double c[3] = {r * v, g * v, b * v};
    for (int i = 0; i < 3; i++) out[i] = (unsigned char)(c[i] < 255.0 ? c[i] : 255.0);
    out[3] = (unsigned char)(e + 128);
}

void gr_viewer_base64(gr_strbuf *b, const unsigned char *data, size_t n)
{
    static const char A[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char chunk[4097];
    size_t k = 0;
    for (size_t i = 0; i < n; i += 3) {
        const unsigned v = (unsigned)data[i] << 16 | (i + 1 < n ? (unsigned)data[i + 1] << 8 : 0u) |
                           (i + 2 < n ? (unsigned)data[i + 2] : 0u);
        chunk[k++] = A[v >> 18 & 63];
        chunk[k++] = A[v >> 12 & 63];
        chunk[k++] = i + 1 < n ? A[v >> 6 & 63] : '=';
        chunk[k++] = i + 2 < n ? A[v & 63] : '=';
        if (k >= sizeof chunk - 5) {
            chunk[k] = 0;
            gr_sb_puts(b, chunk);
            k = 0;
        }
    }
    chunk[k] = 0;
    gr_sb_puts(b, chunk);
}

/* The R, G, B of img times gain, box-shrunk by the integer factor step. */
static gr_image *shrink(const gr_image *img, int step, double gain)
{
    int rgb[3];
    gr_metrics_pick_rgb(img, rgb);
    const int w = img->width / step, h = img->height / step;
    gr_image *o = gr_image_create(w, h, 3, NULL);
    if (!o) return NULL;
    const double norm = gain / (double)(step * step);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                double s = 0;
                for (int j = 0; j < step; j++)
                    for (int i = 0; i < step; i++)
                        s += img->pixels[((size_t)(y * step + j) * (size_t)img->width + (size_t)(x * step + i)) *
                                             (size_t)img->nchannels + (size_t)rgb[c]];
                o->pixels[((size_t)y * (size_t)w + (size_t)x) * 3 + (size_t)c] = (float)(s * norm);
            }
    return o;
}

/* Reads a whole file (the PNG just written) into memory. */
static gr_status slurp(const char *path, unsigned char **data, size_t *n, gr_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return gr_fail(err, GR_E_IO, "%s: cannot read back", path);
    unsigned char *d = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len == cap) {
            cap = cap ? 2 * cap : 1 << 16;
            unsigned char *nd = realloc(d, cap);
            if (!nd) {
                free(d);
                fclose(f);
                return gr_fail(err, GR_E_NOMEM, "%s: out of memory", path);
            }
            d = nd;
        }
        const size_t got = fread(d + len, 1, cap - len, f);
        len += got;
        if (got == 0) break;
    }
    const int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(d);
        return gr_fail(err, GR_E_IO, "%s: read error", path);
    }
    *data = d;
    *n = len;
    return GR_OK;
}

/* img (display-encoded or RGBE codes as floats in [0, 1]) as a PNG data: URL appended to b,
 * through a temporary file in dir that is removed. */
static gr_status png_url(const char *dir, const gr_image *img, gr_strbuf *b, gr_error *err)
{
    char path[4300];
    static unsigned counter;
    snprintf(path, sizeof path, "%s/.viewer-%ld-%u.png", dir, (long)getpid(), counter++);
    gr_status st = gr_oiio_write(path, img, err);
    if (st != GR_OK) return st;
    unsigned char *data = NULL;
    size_t n = 0;
    st = slurp(path, &data, &n, err);
    unlink(path);
    if (st != GR_OK) return st;
    gr_sb_puts(b, "\"data:image/png;base64,");
    gr_viewer_base64(b, data, n);
    gr_sb_puts(b, "\"");
    free(data);
    return GR_OK;
}

/* The RGBE layout of the page: W x 2H, mantissas above, exponents (in R, G and B) below. */
static gr_status rgbe_url(const char *dir, const gr_image *lin, gr_strbuf *b, gr_error *err)
{
    const int w = lin->width, h = lin->height;
    gr_image *e = gr_image_create(w, 2 * h, 3, NULL);
    if (!e) return gr_fail(err, GR_E_NOMEM, "report: out of memory for the comparison's images");
    for (size_t p = 0; p < (size_t)w * (size_t)h; p++) {
        unsigned char q[4];
        const float *v = lin->pixels + 3 * p;
        gr_viewer_rgbe(v[0], v[1], v[2], q);
        for (int c = 0; c < 3; c++) {
            e->pixels[3 * p + (size_t)c] = (float)q[c] / 255.0f;
            e->pixels[3 * ((size_t)w * (size_t)h + p) + (size_t)c] = (float)q[3] / 255.0f;
        }
    }
    gr_status st = png_url(dir, e, b, err);
    gr_image_destroy(e);
    return st;
}

/* A name as a JavaScript string literal inside a <script> (no "</", no quotes, ASCII). */
static void js_string(gr_strbuf *b, const char *s)
{
    gr_sb_puts(b, "\"");
    for (; *s; s++) {
        const unsigned char ch = (unsigned char)*s;
        if (ch < 0x20 || ch >= 0x7f || ch == '"' || ch == '\\' || ch == '<' || ch == '>' || ch == '&')
            gr_sb_printf(b, "\\u%04x", ch);
        else {
            char one[2] = {(char)ch, 0};
            gr_sb_puts(b, one);
        }
    }
    gr_sb_puts(b, "\"");
}

gr_status gr_viewer_write(const char *dir, const gr_image *ref, const gr_viewer_item *items, int n, double exposure,
                          gr_strbuf *html, gr_error *err)
{
    if (!dir || !ref || !items || n < 1 || !html) return gr_fail(err, GR_E_INPUT, "viewer: missing input");
    for (int k = 0; k < n; k++)
        if (!items[k].test || items[k].test->width != ref->width || items[k].test->height != ref->height)
            return gr_fail(err, GR_E_INPUT, "viewer: technique %s: image size differs from the reference's",
                           items[k].name ? items[k].name : "?");
    const int step = (ref->width + GR_VIEWER_MAX_WIDTH - 1) / GR_VIEWER_MAX_WIDTH;
    gr_strbuf data;
    gr_sb_init(&data);
    gr_image *r = shrink(ref, step, 1.0), *t = NULL, *hs = NULL;
    gr_status st = GR_OK;
    if (!r) {
        st = gr_fail(err, GR_E_NOMEM, "report: out of memory for the comparison");
        goto done;
    }
    const int w = r->width, h = r->height;
    gr_sb_printf(&data, "window.GRV_DATA = {w: %d, h: %d, step: %d, exposure: %.9g, truth: ", w, h, step, exposure);
    if ((st = rgbe_url(dir, r, &data, err)) != GR_OK) goto done;
    gr_sb_puts(&data, ",\ntech: [");
    for (int k = 0; k < n; k++) {
        const gr_viewer_item *it = &items[k];
        gr_image_destroy(t);
        gr_image_destroy(hs);
        hs = NULL;
        t = shrink(it->test, step, 1.0);
        if (!t) {
            st = gr_fail(err, GR_E_NOMEM, "report: out of memory for the comparison");
            goto done;
        }
        gr_sb_puts(&data, k ? ",\n{name: " : "\n{name: ");
        js_string(&data, it->name);
        gr_sb_printf(&data, ", scale: %.9g, flipMean: %.6g, img: ", it->scale, it->flip_map ? it->flip_mean : 0.0);
        if ((st = rgbe_url(dir, t, &data, err)) != GR_OK) goto done;
        gr_sb_puts(&data, ", flip: ");
        if (it->flip_map) { /* the page's copy at the page's size */
            hs = step > 1 ? shrink(it->flip_map, step, 1.0) : NULL;
            if (step > 1 && !hs) {
                st = gr_fail(err, GR_E_NOMEM, "report: out of memory for the comparison");
                goto done;
            }
            if ((st = png_url(dir, hs ? hs : it->flip_map, &data, err)) != GR_OK) goto done;
        } else {
            gr_sb_puts(&data, "null");
        }
        gr_sb_puts(&data, "}");
    }
    gr_sb_puts(&data, "]};\n");
    if ((st = gr_sb_status(&data, "the comparison's data", err)) != GR_OK) goto done;

    /* The block: controls, canvas (an integer enlargement of small images up to ~960 px), help. */
    int up = 960 / w;
    if (up < 1) up = 1;
    gr_sb_printf(html, "<style>%s</style>\n", CSS);
    gr_sb_puts(html, "<h2 id=\"compare\">Compare interactively</h2>\n<div id=\"grv\">\n<div class=\"vctl\">\n"
                     "<label>technique <select id=\"grv-tech\">");
    for (int k = 0; k < n; k++) {
        gr_sb_printf(html, "<option value=\"%d\">", k);
        gr_sb_htmlf(html, "%d %s", k + 1, items[k].name);
        gr_sb_puts(html, "</option>");
    }
    gr_sb_puts(html, "</select></label>\n"
                     "<span><label><input type=\"radio\" name=\"grv-mode\" value=\"flip\" checked> flip</label> "
                     "<label><input type=\"radio\" name=\"grv-mode\" value=\"wipe\"> wipe</label> "
                     "<label><input type=\"radio\" name=\"grv-mode\" value=\"flipmap\"> FLIP map</label></span>\n"
                     "<label>wipe <input type=\"range\" id=\"grv-wipe\" min=\"0\" max=\"1000\" value=\"500\"></label>\n"
                     "<label>exposure <input type=\"range\" id=\"grv-ev\" min=\"-100\" max=\"100\" value=\"0\"> "
                     "<span id=\"grv-evv\" class=\"mono\">+0.0 EV</span></label>\n"
                     "<button id=\"grv-reset\" type=\"button\">reset view</button>\n</div>\n");
    gr_sb_printf(html, "<canvas id=\"grv-canvas\" width=\"%d\" height=\"%d\" tabindex=\"0\"></canvas>\n", w * up,
                 h * up);
    gr_sb_puts(html, "<div id=\"grv-label\" class=\"mono\">loading...</div>\n<div id=\"grv-px\" class=\"mono\">"
                     "&nbsp;</div>\n<p class=\"sub\">Click the image or press space (or f) to flip between the "
                     "ground truth and the technique (times its fitted a); w: wipe (the slider, or click where "
                     "the line goes); m: the FLIP map; wheel or +/-: zoom, drag: pan, 0: reset; [ and ]: "
                     "exposure -/+ 0.5 EV; 1-9: technique. The images are the linear renders, tone mapped here "
                     "(exposure, sRGB); the FLIP map is HDR-FLIP of the technique x a against the truth (magma: "
                     "black 0, yellow 1; it does not change with the exposure).");
    if (step > 1) gr_sb_printf(html, " Shown at 1/%d of the render's size (box filter).", step);
    gr_sb_puts(html, "</p>\n</div>\n<script>\n");
    gr_sb_puts(html, gr_sb_str(&data));
    for (size_t i = 0; i < sizeof JS / sizeof JS[0]; i++) gr_sb_puts(html, JS[i]);
    gr_sb_puts(html, "</script>\n");
done:
    gr_sb_free(&data);
    gr_image_destroy(r);
    gr_image_destroy(t);
    gr_image_destroy(hs);
    return st;
}
