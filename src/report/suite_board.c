/* The suite leaderboard (suite_board.h): aggregates, index.html, metrics.json. */
#include "report/suite_board.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/outfile.h"
#include "report/html.h"
#include "report/report.h"

void gr_suite_board_aggregate(const gr_suite_board_input *in, gr_suite_aggregate *agg, int *order)
{
    const int nt = in->n_techniques, nc = in->suite->n_cases;
    for (int k = 0; k < nt; k++) {
        gr_suite_aggregate *a = &agg[k];
        double sum = 0.0, sums[2] = {0.0, 0.0};
        int ns[2] = {0, 0};
        memset(a, 0, sizeof *a);
        a->worst = NAN;
        a->worst_case = -1;
        for (int c = 0; c < nc; c++) {
            const double v = in->verdict[c * nt + k];
            if (!isfinite(v)) {
                a->n_failed++;
                continue;
            }
            const int sp = in->suite->cases[c].split == GR_SPLIT_TEST;
            sum += v;
            sums[sp] += v;
            ns[sp]++;
            a->n_scored++;
            if (a->worst_case < 0 || v > a->worst) {
                a->worst = v;
                a->worst_case = c;
            }
        }
        a->mean = a->n_scored ? sum / a->n_scored : NAN;
        a->mean_train = ns[0] ? sums[0] / ns[0] : NAN;
        a->mean_test = ns[1] ? sums[1] / ns[1] : NAN;
    }
    for (int k = 0; k < nt; k++) order[k] = k;
    /* insertion sort: stable, and n is small */
    for (int i = 1; i < nt; i++) {
        const int x = order[i];
        int j = i - 1;
        for (; j >= 0; j--) {
            const gr_suite_aggregate *p = &agg[order[j]], *q = &agg[x];
            const int pf = p->n_failed > 0 || !isfinite(p->mean), qf = q->n_failed > 0 || !isfinite(q->mean);
            const int after = pf != qf ? pf > qf : (!pf && p->mean > q->mean);
            if (!after) break;
            order[j + 1] = order[j];
        }
        order[j + 1] = x;
    }
}

static const char *css =
    "body{font-family:sans-serif;background:#111;color:#ddd;margin:1.5em}a{color:#8cf}"
    "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #444;padding:4px 6px;text-align:center}"
    "th{background:#222}td.l{text-align:left}img{display:block;margin:auto;image-rendering:pixelated}"
    ".best{color:#7f7;font-weight:bold}.fail{color:#f77}.test{background:#1a2230}small{color:#999}";

static void cell_number(gr_strbuf *b, double v)
{
    if (isfinite(v)) gr_sb_printf(b, "%.4g", v);
    else gr_sb_puts(b, "&ndash;");
}

/* The ranking: one row per technique, best first. */
static void html_ranking(gr_strbuf *b, const gr_suite_board_input *in, const gr_suite_aggregate *agg, const int *order)
{
    gr_sb_puts(b, "<h2>Ranking over the suite</h2><table><tr><th>rank</th><th>technique</th><th>mean verdict</th>"
                  "<th>worst verdict</th><th>worst case</th><th>mean, train cases</th><th>mean, test cases</th>"
                  "<th>failed in</th></tr>\n");
    for (int r = 0; r < in->n_techniques; r++) {
        const int k = order[r];
        const gr_suite_aggregate *a = &agg[k];
        gr_sb_printf(b, "<tr><td>%d</td><td class=\"l\">", r + 1);
        gr_sb_html(b, in->techniques[k]);
        gr_sb_puts(b, "</td><td>");
        cell_number(b, a->mean);
        gr_sb_puts(b, "</td><td>");
        cell_number(b, a->worst);
        gr_sb_puts(b, "</td><td class=\"l\">");
        if (a->worst_case >= 0) gr_sb_html(b, in->suite->cases[a->worst_case].name);
        gr_sb_puts(b, "</td><td>");
        cell_number(b, a->mean_train);
        gr_sb_puts(b, "</td><td>");
        cell_number(b, a->mean_test);
        gr_sb_printf(b, "</td><td%s>%d of %d cases</td></tr>\n", a->n_failed ? " class=\"fail\"" : "", a->n_failed,
                     in->suite->n_cases);
    }
    gr_sb_puts(b, "</table>\n");
}

/* The case x technique table: the truth's thumbnail, then each technique's with its verdict. */
static void html_table(gr_strbuf *b, const gr_suite_board_input *in, const gr_suite_aggregate *agg, const int *order)
{
    const int nt = in->n_techniques;
    gr_sb_puts(b, "<h2>Cases</h2><p>Each cell: the technique's image (x its fitted scale, the ground truth's "
                  "exposure) and its verdict; the best of a row in green. A case's name opens its own report.</p>"
                  "<table><tr><th>case</th><th>split</th><th>ground truth</th>");
    if (in->constant) gr_sb_puts(b, "<th>constant image<br><small>(baseline)</small></th>");
    for (int r = 0; r < nt; r++) {
        gr_sb_puts(b, "<th>");
        gr_sb_html(b, in->techniques[order[r]]);
        gr_sb_puts(b, "</th>");
    }
    gr_sb_puts(b, "</tr>\n");
    for (int c = 0; c < in->suite->n_cases; c++) {
        const gr_suite_case *sc = &in->suite->cases[c];
        int best = -1;
        for (int k = 0; k < nt; k++) {
            const double v = in->verdict[c * nt + k];
            if (isfinite(v) && (best < 0 || v < in->verdict[c * nt + best])) best = k;
        }
        gr_sb_printf(b, "<tr%s><td class=\"l\"><a href=\"cases/", sc->split == GR_SPLIT_TEST ? " class=\"test\"" : "");
        gr_sb_html(b, sc->name);
        gr_sb_puts(b, "/index.html\">");
        gr_sb_html(b, sc->name);
        gr_sb_printf(b, "</a></td><td>%s</td><td><img src=\"cases/", gr_split_name(sc->split));
        gr_sb_html(b, sc->name);
        gr_sb_puts(b, "/reference.png\" width=\"160\" alt=\"ground truth\"></td>");
        if (in->constant) {
            gr_sb_puts(b, "<td>");
            cell_number(b, in->constant[c]);
            gr_sb_puts(b, "</td>");
        }
        for (int r = 0; r < nt; r++) {
            const int k = order[r], i = c * nt + k;
            const double v = in->verdict[i];
            if (!isfinite(v)) {
                gr_sb_puts(b, "<td class=\"fail\">FAILED");
                if (in->reasons && in->reasons[i]) {
                    gr_sb_puts(b, "<br><small>");
                    gr_sb_html(b, in->reasons[i]);
                    gr_sb_puts(b, "</small>");
                }
                gr_sb_puts(b, "</td>");
                continue;
            }
            char stem[80];
            gr_report_tech_stem(in->techniques[k], stem, sizeof stem);
            gr_sb_puts(b, "<td><img src=\"cases/");
            gr_sb_html(b, sc->name);
            gr_sb_puts(b, "/");
            gr_sb_html(b, stem);
            gr_sb_puts(b, ".png\" width=\"160\" alt=\"");
            gr_sb_html(b, in->techniques[k]);
            gr_sb_printf(b, "\"><span%s>", k == best ? " class=\"best\"" : "");
            cell_number(b, v);
            gr_sb_puts(b, "</span>");
            if (in->error_fit && in->structure)
                gr_sb_printf(b, "<br><small>err %.3g, struct %.3g</small>", in->error_fit[i], in->structure[i]);
            gr_sb_puts(b, "</td>");
        }
        gr_sb_puts(b, "</tr>\n");
    }
    static const char *const rows[] = {"mean", "worst", "mean, train", "mean, test"};
    for (int w = 0; w < 4; w++) {
        gr_sb_printf(b, "<tr><th colspan=\"%d\">%s</th>", in->constant ? 4 : 3, rows[w]);
        for (int r = 0; r < nt; r++) {
            const gr_suite_aggregate *a = &agg[order[r]];
            const double v = w == 0 ? a->mean : w == 1 ? a->worst : w == 2 ? a->mean_train : a->mean_test;
            gr_sb_puts(b, "<td>");
            cell_number(b, v);
            if (w == 1 && a->worst_case >= 0) {
                gr_sb_puts(b, "<br><small>");
                gr_sb_html(b, in->suite->cases[a->worst_case].name);
                gr_sb_puts(b, "</small>");
            }
            gr_sb_puts(b, "</td>");
        }
        gr_sb_puts(b, "</tr>\n");
    }
    gr_sb_puts(b, "</table>\n");
}

static gr_status write_html(const char *dir, const gr_suite_board_input *in, const gr_suite_aggregate *agg,
                            const int *order, gr_error *err)
{
    gr_strbuf b;
    gr_sb_init(&b);
    const gr_suite *s = in->suite;
    gr_sb_printf(&b, "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>godrays suite ");
    gr_sb_html(&b, s->name);
    gr_sb_printf(&b, "</title><style>%s</style></head><body><h1>Suite leaderboard: ", css);
    gr_sb_html(&b, s->name);
    gr_sb_puts(&b, "</h1><p>");
    gr_sb_html(&b, s->description);
    gr_sb_printf(&b, "</p><p>%d cases (%d train, %d test) from <code>", s->n_cases, gr_suite_count(s, GR_SPLIT_TRAIN),
                 gr_suite_count(s, GR_SPLIT_TEST));
    gr_sb_html(&b, s->path);
    gr_sb_puts(&b, "</code>. Score: the verdict of each case's leaderboard ((error after the fit + structure score) "
                   "/ 2, lower is better; docs/metrics.md); the aggregate is its mean over the cases and its worst "
                   "case (docs/report.md \"Suites\").</p>\n");
    html_ranking(&b, in, agg, order);
    html_table(&b, in, agg, order);
    if (in->command_line) {
        gr_sb_puts(&b, "<p><small>");
        gr_sb_html(&b, in->command_line);
        if (in->seconds >= 0) gr_sb_printf(&b, " &mdash; %.1f s", in->seconds);
        gr_sb_puts(&b, "</small></p>");
    }
    gr_sb_puts(&b, "</body></html>\n");
    char path[4200];
    snprintf(path, sizeof path, "%s/index.html", dir);
    gr_status st = gr_sb_status(&b, "index.html", err);
    if (st == GR_OK) st = gr_outfile_write(path, gr_sb_str(&b), -1, err);
    gr_sb_free(&b);
    return st;
}

static cJSON *num(double v)
{
    return isfinite(v) ? cJSON_CreateNumber(v) : cJSON_CreateNull();
}

static gr_status write_json(const char *dir, const gr_suite_board_input *in, const gr_suite_aggregate *agg,
                            const int *order, gr_error *err)
{
    const gr_suite *s = in->suite;
    const int nt = in->n_techniques;
    cJSON *root = cJSON_CreateObject(), *su = cJSON_AddObjectToObject(root, "suite");
    cJSON_AddStringToObject(su, "name", s->name);
    cJSON_AddStringToObject(su, "path", s->path);
    cJSON_AddStringToObject(su, "description", s->description);
    cJSON_AddStringToObject(root, "score", "verdict");
    if (in->command_line) cJSON_AddStringToObject(root, "command_line", in->command_line);
    cJSON *cases = cJSON_AddArrayToObject(root, "cases");
    for (int c = 0; c < s->n_cases; c++) {
        const gr_suite_case *sc = &s->cases[c];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(cases, o);
        cJSON_AddStringToObject(o, "name", sc->name);
        cJSON_AddStringToObject(o, "split", gr_split_name(sc->split));
        cJSON_AddStringToObject(o, "scene", sc->scene_path);
        cJSON_AddNumberToObject(o, "width", sc->scene.camera.width);
        cJSON_AddNumberToObject(o, "height", sc->scene.camera.height);
        char rel[GR_SUITE_NAME_MAX + 32];
        snprintf(rel, sizeof rel, "cases/%s/metrics.json", sc->name);
        cJSON_AddStringToObject(o, "metrics", rel);
        if (in->constant) cJSON_AddItemToObject(o, "constant_verdict", num(in->constant[c]));
        cJSON *t = cJSON_AddObjectToObject(o, "techniques");
        for (int k = 0; k < nt; k++) {
            const int i = c * nt + k;
            cJSON *e = cJSON_AddObjectToObject(t, in->techniques[k]);
            cJSON_AddItemToObject(e, "verdict", num(in->verdict[i]));
            if (in->error_fit) cJSON_AddItemToObject(e, "error_fit", num(in->error_fit[i]));
            if (in->structure) cJSON_AddItemToObject(e, "structure", num(in->structure[i]));
            if (in->gpu_ms) cJSON_AddItemToObject(e, "gpu_ms", num(in->gpu_ms[i]));
            if (!isfinite(in->verdict[i]))
                cJSON_AddStringToObject(e, "failed", in->reasons && in->reasons[i] ? in->reasons[i] : "failed");
        }
    }
    cJSON *ag = cJSON_AddArrayToObject(root, "aggregate"); /* best first */
    for (int r = 0; r < nt; r++) {
        const int k = order[r];
        const gr_suite_aggregate *a = &agg[k];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(ag, o);
        cJSON_AddStringToObject(o, "technique", in->techniques[k]);
        cJSON_AddNumberToObject(o, "rank", r + 1);
        cJSON_AddItemToObject(o, "mean_verdict", num(a->mean));
        cJSON_AddItemToObject(o, "worst_verdict", num(a->worst));
        if (a->worst_case >= 0) cJSON_AddStringToObject(o, "worst_case", s->cases[a->worst_case].name);
        else cJSON_AddNullToObject(o, "worst_case");
        cJSON_AddItemToObject(o, "mean_verdict_train", num(a->mean_train));
        cJSON_AddItemToObject(o, "mean_verdict_test", num(a->mean_test));
        cJSON_AddNumberToObject(o, "cases_scored", a->n_scored);
        cJSON_AddNumberToObject(o, "cases_failed", a->n_failed);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    if (!text) return gr_fail(err, GR_E_NOMEM, "metrics.json: out of memory");
    char path[4200];
    snprintf(path, sizeof path, "%s/metrics.json", dir);
    gr_status st = gr_outfile_write(path, text, -1, err);
    free(text);
    return st;
}

gr_status gr_suite_board_write(const char *dir, const gr_suite_board_input *in, gr_error *err)
{
    const int nt = in->n_techniques;
    if (nt < 1 || nt > GR_SUITE_BOARD_MAX_TECHNIQUES || !in->suite || !in->verdict)
        return gr_fail(err, GR_E_RUNTIME, "suite leaderboard: bad input (%d techniques)", nt);
    gr_suite_aggregate agg[GR_SUITE_BOARD_MAX_TECHNIQUES];
    int order[GR_SUITE_BOARD_MAX_TECHNIQUES];
    gr_suite_board_aggregate(in, agg, order);
    gr_status st = gr_report_make_dir(dir, err);
    if (st == GR_OK) st = write_json(dir, in, agg, order, err);
    if (st == GR_OK) st = write_html(dir, in, agg, order, err);
    return st;
}
