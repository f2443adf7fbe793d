/* The small HTTP server of `godrays watch` (libmicrohttpd, docs/dependencies.md): one page,
 * one JSON document and a few named PNG images, served from memory on 127.0.0.1 only, by
 * libmicrohttpd's own thread. The watch loop replaces what is served (gr_watch_server_publish)
 * whenever a render finishes; a request always sees one whole publication (a mutex).
 *
 * URLs: "/" the page (text/html), "/state.json" the JSON, "/img/NAME.png" an image (a query
 * string such as "?id=7" is ignored: the page uses it to defeat caching). Anything else is 404;
 * every answer says Cache-Control: no-store. Library code: it prints nothing. */
#ifndef GR_WATCH_SERVER_H
#define GR_WATCH_SERVER_H

#include <stddef.h>

#include "common/status.h"

#define GR_WATCH_MAX_IMAGES 8

typedef struct gr_watch_server gr_watch_server;

/* One named image: PNG bytes (the server copies them). */
typedef struct gr_watch_blob {
    const char *name;           /* "test": served as /img/test.png */
    const unsigned char *data;
    size_t len;
} gr_watch_blob;

/* Listens on 127.0.0.1:port (0: a free port the system picks; gr_watch_server_port says which)
 * and serves page (copied) at "/", "{}" at /state.json until the first publication.
 * GR_E_USAGE naming the port when it cannot be bound (in use, or privileged); GR_E_IO else. */
gr_status gr_watch_server_create(int port, const char *page, gr_watch_server **out, gr_error *err);
/* The port listened on. */
int gr_watch_server_port(const gr_watch_server *s);
/* Serves json and the n images from now on (copied; images not named keep their last
 * bytes, so an unchanged truth need not be sent again). GR_E_NOMEM, GR_E_INPUT for a bad
 * name or more than GR_WATCH_MAX_IMAGES names. */
gr_status gr_watch_server_publish(gr_watch_server *s, const char *json, const gr_watch_blob *images, int n,
                                  gr_error *err);
/* Stops the server (its thread joined, the socket closed) and frees it; accepts NULL. */
void gr_watch_server_destroy(gr_watch_server *s);

#endif
