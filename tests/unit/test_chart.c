/* report/chart: the interactive chart's HTML. Checked against what the page needs, written out
 * by hand: the library file inlined verbatim (a stand-in file given by GODRAYS_CHARTJS), with
 * any "</script" it holds broken so that it cannot end the element early; every text of the
 * caller inside the data as JSON whose '<' is \u003c (a title "</script><b>" cannot close the
 * script or inject markup); a point the log axis cannot place sent as null (not drawn) but
 * kept so that point indices stay row indices; the PNG fallback always present; a missing
 * library: no script at all, the fallback image and a reason naming the file and the package;
 * the row attributes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "report/chart.h"

static int count(const char *s, const char *what)
{
    int n = 0;
    for (const char *p = strstr(s, what); p; p = strstr(p + 1, what)) n++;
    return n;
}

int main(void)
{
    char lib[] = "/tmp/gr_test_chart_XXXXXX";
    int fd = mkstemp(lib);
    CHECK(fd >= 0);
    const char *body = "/*LIBSTART*/var Chart=function(){};var s='</script>';/*LIBEND*/";
    CHECK(write(fd, body, strlen(body)) == (ssize_t)strlen(body));
    close(fd);
    setenv("GODRAYS_CHARTJS", lib, 1);
    CHECK(!strcmp(gr_chart_library_path(), lib));

    gr_chart_point pts[3];
    memset(pts, 0, sizeof pts);
    pts[0] = (gr_chart_point){.series = 0, .x = 1.5, .y = 0.25, .on_front = 1};
    snprintf(pts[0].title, sizeof pts[0].title, "</script><b>x</b>");
    snprintf(pts[0].lines, sizeof pts[0].lines, "line \"one\"\nline two");
    snprintf(pts[0].thumb, sizeof pts[0].thumb, "thumbs/p0.png");
    pts[1] = (gr_chart_point){.series = 1, .x = 0.0, .y = 0.5}; /* x <= 0: not on a log axis */
    pts[2] = (gr_chart_point){.series = 1, .x = 3.0, .y = 0.125};
    gr_chart c;
    memset(&c, 0, sizeof c);
    c.id = "t1";
    c.title = "a & b";
    c.x_label = "time";
    c.y_label = "error";
    c.png = "fronts.png";
    c.log_y = 1;
    c.n_series = 2;
    snprintf(c.series[0].name, sizeof c.series[0].name, "shafts tuned");
    snprintf(c.series[1].name, sizeof c.series[1].name, "shafts untuned");
    c.series[1].hollow = 1;
    c.n_points = 3;
    c.points = pts;

    gr_strbuf b;
    gr_sb_init(&b);
    char why[512] = "unset";
    CHECK(gr_chart_html(&b, &c, why, sizeof why) == 1);
    CHECK(why[0] == '\0');
    const char *h = gr_sb_str(&b);
    CHECK(strstr(h, "/*LIBSTART*/var Chart=function(){};var s='<\\/script>';/*LIBEND*/") != NULL);
    /* the only "</script" are the closings of the page's two script elements */
    CHECK_MSG(count(h, "</script") == 2, "%d", count(h, "</script"));
    CHECK(strstr(h, "\"t\":\"\\u003c/script\\u003e\\u003cb\\u003ex\\u003c/b\\u003e\"") != NULL);
    CHECK(strstr(h, "\"d\":[\"line \\\"one\\\"\",\"line two\"]") != NULL);
    CHECK(strstr(h, "{\"s\":0,\"x\":1.5,\"y\":0.25,\"f\":1,") != NULL);
    CHECK(strstr(h, "{\"s\":1,\"x\":null,\"y\":null,") != NULL);
    CHECK(strstr(h, "{\"s\":1,\"x\":3,\"y\":0.125,\"f\":0,") != NULL);
    CHECK(strstr(h, "\"a \\u0026 b\"") != NULL);
    CHECK(strstr(h, "\"hollow\":1") != NULL);
    CHECK(strstr(h, "<img src=\"fronts.png\"") != NULL);
    CHECK(strstr(h, "id=\"t1-canvas\"") && strstr(h, "id=\"t1-status\"") && strstr(h, "grChart({\"id\":\"t1\""));
    gr_sb_free(&b);

    /* the library missing: the fallback and why, no script */
    unlink(lib);
    CHECK(gr_chart_html(&b, &c, why, sizeof why) == 0);
    h = gr_sb_str(&b);
    CHECK_MSG(strstr(why, lib) && strstr(why, "libjs-chart.js"), "why: %s", why);
    CHECK(strstr(h, "<script") == NULL);
    CHECK(strstr(h, "<img src=\"fronts.png\"") != NULL);
    CHECK(strstr(h, "libjs-chart.js") != NULL);
    gr_sb_free(&b);

    gr_chart_row_attrs(&b, "t1", 7);
    CHECK(!strcmp(gr_sb_str(&b), " data-gr-chart=\"t1\" data-gr-point=\"7\""));
    gr_sb_free(&b);
    char name[64];
    gr_chart_thumb_name(12, name, sizeof name);
    CHECK(!strcmp(name, "thumbs/p12.png"));
    CHECK_DONE();
}
