/* libmicrohttpd serving one page, one JSON and named PNGs from memory (server.h). */
#define _GNU_SOURCE
#include "watch/server.h"

#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

typedef struct blob {
    char name[32];
    unsigned char *data;
    size_t len;
} blob;

struct gr_watch_server {
    struct MHD_Daemon *daemon;
    int port;
    pthread_mutex_t lock; /* guards everything below */
    char *page, *json;
    blob images[GR_WATCH_MAX_IMAGES];
    int n_images;
};

/* Answers with a copy of data (the lock is held by the caller: the copy is taken inside it). */
static enum MHD_Result answer(struct MHD_Connection *c, unsigned code, const char *type, const void *data, size_t len)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(len, (void *)data, MHD_RESPMEM_MUST_COPY);
    if (!r) return MHD_NO;
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    enum MHD_Result ret = MHD_queue_response(c, code, r);
    MHD_destroy_response(r);
    return ret;
}

static enum MHD_Result handle(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                              const char *version, const char *upload, size_t *upload_size, void **con_cls)
{
    (void)version, (void)upload, (void)upload_size, (void)con_cls;
    gr_watch_server *s = cls;
    static const char not_found[] = "not found\n";
    if (strcmp(method, "GET") && strcmp(method, "HEAD"))
        return answer(c, MHD_HTTP_METHOD_NOT_ALLOWED, "text/plain", "GET only\n", 9);
    enum MHD_Result ret;
    pthread_mutex_lock(&s->lock);
    if (!strcmp(url, "/") || !strcmp(url, "/index.html")) {
        ret = answer(c, MHD_HTTP_OK, "text/html; charset=utf-8", s->page, strlen(s->page));
    } else if (!strcmp(url, "/state.json")) {
        const char *j = s->json ? s->json : "{}";
        ret = answer(c, MHD_HTTP_OK, "application/json", j, strlen(j));
    } else {
        const blob *b = NULL;
        size_t n = strlen(url);
        if (!strncmp(url, "/img/", 5) && n > 9 && !strcmp(url + n - 4, ".png"))
            for (int i = 0; i < s->n_images && !b; i++)
                if (strlen(s->images[i].name) == n - 9 && !strncmp(url + 5, s->images[i].name, n - 9)) b = &s->images[i];
        ret = b ? answer(c, MHD_HTTP_OK, "image/png", b->data, b->len)
                : answer(c, MHD_HTTP_NOT_FOUND, "text/plain", not_found, sizeof not_found - 1);
    }
    pthread_mutex_unlock(&s->lock);
    return ret;
}

/* The listening socket on 127.0.0.1:port, made here so that a failure names its reason. */
static gr_status listen_on(int port, int *fd_out, int *port_out, gr_error *err)
{
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return gr_fail(err, GR_E_IO, "--port %d: socket: %s", port, strerror(errno));
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one); /* a restart right after a stop */
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((unsigned short)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK); /* never reachable from another machine */
    if (bind(fd, (struct sockaddr *)&a, sizeof a) || listen(fd, 32)) {
        int e = errno;
        close(fd);
        return gr_fail(err, GR_E_USAGE, "--port %d: cannot listen on 127.0.0.1:%d: %s", port, port, strerror(e));
    }
    socklen_t len = sizeof a;
    if (getsockname(fd, (struct sockaddr *)&a, &len)) {
        int e = errno;
        close(fd);
        return gr_fail(err, GR_E_IO, "--port %d: getsockname: %s", port, strerror(e));
    }
    *fd_out = fd;
    *port_out = ntohs(a.sin_port);
    return GR_OK;
}

gr_status gr_watch_server_create(int port, const char *page, gr_watch_server **out, gr_error *err)
{
    *out = NULL;
    if (port < 0 || port > 65535) return gr_fail(err, GR_E_USAGE, "--port %d: expected 0..65535", port);
    gr_watch_server *s = calloc(1, sizeof *s);
    if (!s || !(s->page = strdup(page ? page : ""))) {
        free(s);
        return gr_fail(err, GR_E_NOMEM, "watch server: out of memory");
    }
    pthread_mutex_init(&s->lock, NULL);
    int fd = -1;
    gr_status st = listen_on(port, &fd, &s->port, err);
    if (st == GR_OK) {
        /* one thread of libmicrohttpd's own polls the socket; the daemon owns fd from here */
        s->daemon = MHD_start_daemon(MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_AUTO, 0, NULL, NULL, handle, s,
                                     MHD_OPTION_LISTEN_SOCKET, (MHD_socket)fd, MHD_OPTION_CONNECTION_TIMEOUT,
                                     (unsigned)10, MHD_OPTION_END);
        if (!s->daemon) {
            close(fd);
            st = gr_fail(err, GR_E_IO, "--port %d: the HTTP server (libmicrohttpd) did not start", port);
        }
    }
    if (st != GR_OK) {
        gr_watch_server_destroy(s);
        return st;
    }
    *out = s;
    return GR_OK;
}

int gr_watch_server_port(const gr_watch_server *s) { return s ? s->port : 0; }

static blob *find_or_add(gr_watch_server *s, const char *name)
{
    for (int i = 0; i < s->n_images; i++)
        if (!strcmp(s->images[i].name, name)) return &s->images[i];
    if (s->n_images >= GR_WATCH_MAX_IMAGES) return NULL;
    blob *b = &s->images[s->n_images++];
    snprintf(b->name, sizeof b->name, "%s", name);
    return b;
}

gr_status gr_watch_server_publish(gr_watch_server *s, const char *json, const gr_watch_blob *images, int n,
                                  gr_error *err)
{
    /* copies made outside the lock: a request in flight is not held up by a malloc */
    char *j = strdup(json ? json : "{}");
    unsigned char *copies[GR_WATCH_MAX_IMAGES] = {NULL};
    gr_status st = j ? GR_OK : gr_fail(err, GR_E_NOMEM, "watch server: out of memory");
    if (st == GR_OK && n > GR_WATCH_MAX_IMAGES) st = gr_fail(err, GR_E_INPUT, "watch server: more than %d images", GR_WATCH_MAX_IMAGES);
    for (int i = 0; st == GR_OK && i < n; i++) {
        size_t l = strlen(images[i].name);
        if (!l || l >= sizeof((blob *)0)->name || strchr(images[i].name, '/'))
            st = gr_fail(err, GR_E_INPUT, "watch server: bad image name '%s'", images[i].name);
        else if (!(copies[i] = malloc(images[i].len ? images[i].len : 1)))
            st = gr_fail(err, GR_E_NOMEM, "watch server: out of memory");
        else if (images[i].len)
            memcpy(copies[i], images[i].data, images[i].len);
    }
    if (st == GR_OK) {
        pthread_mutex_lock(&s->lock);
        for (int i = 0; i < n && st == GR_OK; i++) {
            blob *b = find_or_add(s, images[i].name);
            if (!b) {
                st = gr_fail(err, GR_E_INPUT, "watch server: more than %d image names", GR_WATCH_MAX_IMAGES);
                break;
            }
            free(b->data);
            b->data = copies[i];
            b->len = images[i].len;
            copies[i] = NULL;
        }
        free(s->json);
        s->json = j;
        j = NULL;
        pthread_mutex_unlock(&s->lock);
    }
    for (int i = 0; i < n && i < GR_WATCH_MAX_IMAGES; i++) free(copies[i]);
    free(j);
    return st;
}

void gr_watch_server_destroy(gr_watch_server *s)
{
    if (!s) return;
    if (s->daemon) MHD_stop_daemon(s->daemon); /* joins its thread and closes the socket */
    pthread_mutex_destroy(&s->lock);
    for (int i = 0; i < s->n_images; i++) free(s->images[i].data);
    free(s->page);
    free(s->json);
    free(s);
}
