/* report/html: the text buffer and HTML escaping. Expected strings are written out by hand
 * from the HTML spec's five special characters (& < > " ') and its rule that control
 * characters have no place in text. */
#include <string.h>

#include "check.h"
#include "report/html.h"

int main(void)
{
    gr_strbuf b;
    gr_sb_init(&b);
    CHECK(!strcmp(gr_sb_str(&b), "")); /* empty buffer reads as "" */

    gr_sb_html(&b, "<script>alert('x & y')</script> \"q\"");
    CHECK_MSG(!strcmp(gr_sb_str(&b), "&lt;script&gt;alert(&#39;x &amp; y&#39;)&lt;/script&gt; &quot;q&quot;"), "got %s",
              gr_sb_str(&b));
    gr_sb_free(&b);

    /* entities are not double-decoded: "&amp;" escapes to "&amp;amp;" */
    gr_sb_html(&b, "&amp;");
    CHECK(!strcmp(gr_sb_str(&b), "&amp;amp;"));
    gr_sb_free(&b);

    /* control characters (other than tab and newline) become U+FFFD; UTF-8 passes through */
    gr_sb_html(&b, "a\x01" "b\tc\nd\x7f" "e \xc3\xa9");
    CHECK_MSG(!strcmp(gr_sb_str(&b), "a\xEF\xBF\xBD" "b\tc\nd\xEF\xBF\xBD" "e \xc3\xa9"), "got %s", gr_sb_str(&b));
    gr_sb_free(&b);

    /* printf that needs more than the internal 512-byte scratch, verbatim and escaped */
    char big[3000];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    big[1000] = '<';
    gr_sb_printf(&b, "[%s]", big);
    CHECK(b.len == strlen(big) + 2);
    CHECK(gr_sb_str(&b)[1001] == '<');
    gr_sb_free(&b);
    gr_sb_htmlf(&b, "%s|%d", big, 42);
    CHECK(b.len == strlen(big) - 1 + 4 + 3);
    CHECK(strstr(gr_sb_str(&b), "&lt;") == gr_sb_str(&b) + 1000);
    CHECK(!strcmp(gr_sb_str(&b) + b.len - 3, "|42"));
    gr_sb_free(&b);

    /* appends accumulate in order; NULL strings append nothing */
    gr_sb_puts(&b, "a");
    gr_sb_puts(&b, NULL);
    gr_sb_html(&b, NULL);
    gr_sb_printf(&b, "%d%s", 1, "b");
    gr_sb_html(&b, "");
    CHECK(!strcmp(gr_sb_str(&b), "a1b"));
    gr_error err = {GR_OK, ""};
    CHECK(gr_sb_status(&b, "t", &err) == GR_OK);
    /* a failed append is sticky and reported once at the end */
    b.failed = 1;
    gr_sb_puts(&b, "more");
    CHECK(!strcmp(gr_sb_str(&b), "a1b"));
    CHECK(gr_sb_status(&b, "page.html", &err) == GR_E_NOMEM);
    CHECK(strstr(err.msg, "page.html") != NULL);
    gr_sb_free(&b);
    gr_sb_free(NULL);
    CHECK(b.data == NULL && b.len == 0 && !b.failed);
    CHECK_DONE();
}
