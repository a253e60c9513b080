/* out.c — output files that are never seen half-written. A regular file (or a name
 * not yet taken) is written to a temporary beside it and renamed over it only once
 * the whole of it is flushed and fsync'd, so a reader sees the old file or the new
 * one: a failed render, a full disk, a kill or two renders racing to one name leave
 * the old file's bytes as they were. Streams and devices ("-", /dev/..., FIFOs) have
 * no "old file" to keep and are written directly; their errors name the path and
 * the system's reason like any other. Temporaries still open when SIGINT, SIGTERM,
 * SIGHUP or SIGXFSZ arrives are removed before the signal takes its usual course.
 *
 * The files of one commit (an image and its mask) replace theirs as a pair: the
 * renames run under an exclusive lock (flock) on each target's directory, taken in
 * one order, so two runs committing to the same names never interleave their renames,
 * and with those signals held back, so a signal cannot remove the second temporary
 * once the first is in place. What no program can stop is SIGKILL (or a power cut)
 * between two renames, microseconds apart: that can leave a new image beside an old
 * mask. */
#define _XOPEN_SOURCE 700   /* realpath, mkstemp, fchmod */
#define _DEFAULT_SOURCE     /* flock */
#include "platform.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

/* ------------------------------------------------------------ signal cleanup */

/* The temporaries now open. A slot is set only once its name is complete and
 * cleared before the name is freed, so the handler reads whole names or NULL. */
#define LIVE_MAX 32
static char *volatile live[LIVE_MAX];

static void on_signal(int sig)
{
    for (int i = 0; i < LIVE_MAX; i++)
        if (live[i]) unlink(live[i]);
    signal(sig, SIG_DFL);
    raise(sig);
}

static void live_add(char *tmp)
{
    static int installed;
    if (!installed) {
        static const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGXFSZ};
        for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
            void (*old)(int) = signal(sigs[i], on_signal);
            if (old == SIG_IGN) signal(sigs[i], SIG_IGN);   /* nohup etc. keep theirs */
        }
        installed = 1;
    }
    for (int i = 0; i < LIVE_MAX; i++)
        if (!live[i]) { live[i] = tmp; return; }
    /* more than LIVE_MAX at once: still atomic, only not cleaned up on a signal */
}

static void live_remove(const char *tmp)
{
    for (int i = 0; i < LIVE_MAX; i++)
        if (live[i] == tmp) live[i] = NULL;
}

/* ------------------------------------------------------------ opening */

static om_status fail(om_diag *d, const char *path, const char *what, int err)
{
    if (d) {
        d->status = OM_E_IO;
        snprintf(d->msg, sizeof d->msg, "%s: %s: %s", path, what, strerror(err));
    }
    return OM_E_IO;
}

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *p = malloc(n);
    if (p) memcpy(p, s, n);
    return p;
}

bool om_out_is_direct(const char *path)
{
    struct stat sb;
    if (!strcmp(path, "-") || !strncmp(path, "/dev/", 5) || !strncmp(path, "/proc/", 6)) return true;
    return stat(path, &sb) == 0 && !S_ISREG(sb.st_mode) && !S_ISDIR(sb.st_mode);
}

/* The file a rename must replace: a symlink's final target (so the link stays a
 * link; a dangling one is followed one step to the file it names), else the path. */
static char *target_of(const char *path)
{
    struct stat sb;
    if (lstat(path, &sb) != 0 || !S_ISLNK(sb.st_mode)) return dup_str(path);
    char *real = realpath(path, NULL);
    if (real) return real;
    size_t n = sb.st_size > 0 ? (size_t)sb.st_size : 4096;
    char *link = malloc(n + 1);
    ssize_t got = link ? readlink(path, link, n + 1) : -1;
    if (got <= 0 || (size_t)got > n) { free(link); return dup_str(path); }
    link[got] = '\0';
    const char *slash = strrchr(path, '/');
    size_t dir = link[0] != '/' && slash ? (size_t)(slash - path) + 1 : 0;
    char *t = malloc(dir + (size_t)got + 1);
    if (t) {
        memcpy(t, path, dir);
        memcpy(t + dir, link, (size_t)got + 1);
    }
    free(link);
    return t;
}

/* "<dir>/.<base>.XXXXXX" beside the target (".ombra.XXXXXX" for a base too long to
 * take eight more characters). */
static char *temp_name(const char *target)
{
    const char *slash = strrchr(target, '/');
    size_t dir = slash ? (size_t)(slash - target) + 1 : 0;
    const char *base = target + dir;
    if (strlen(base) > 200) base = "ombra";
    char *t = malloc(dir + strlen(base) + 9);
    if (!t) return NULL;
    memcpy(t, target, dir);
    sprintf(t + dir, ".%s.XXXXXX", base);
    return t;
}

om_status om_out_open(om_out *o, const char *path, om_diag *d)
{
    memset(o, 0, sizeof *o);
    o->path = path;
    if (!path[0]) return fail(d, "''", "cannot create", ENOENT);
    if (!strcmp(path, "-")) {
        o->f = stdout;
        o->direct = o->is_stdout = true;
        return OM_OK;
    }
    if (om_out_is_direct(path)) {
        o->direct = true;
        if (!(o->f = fopen(path, "wb"))) return fail(d, path, "cannot open", errno);
        return OM_OK;
    }
    struct stat sb;
    mode_t mode;
    o->target = target_of(path);
    o->tmp = o->target ? temp_name(o->target) : NULL;
    if (!o->tmp) { om_out_discard(o); return fail(d, path, "cannot create", ENOMEM); }
    if (stat(o->target, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        om_out_discard(o);
        return fail(d, path, "cannot create", EISDIR);
    }
    if (stat(o->target, &sb) == 0) {
        mode = sb.st_mode & 07777;   /* a replaced file keeps its permissions */
    } else {
        mode_t mask = umask(0);
        umask(mask);
        mode = 0666 & ~mask;
    }
    int fd = mkstemp(o->tmp);
    if (fd < 0) {
        int err = errno;
        free(o->tmp);
        o->tmp = NULL;
        om_out_discard(o);
        return fail(d, path, "cannot create", err);
    }
    live_add(o->tmp);
    if (fchmod(fd, mode) != 0 || !(o->f = fdopen(fd, "wb"))) {
        int err = errno;
        if (!o->f) close(fd);
        om_out_discard(o);
        return fail(d, path, "cannot create", err);
    }
    return OM_OK;
}

/* ------------------------------------------------------------ writing */

bool om_out_write(om_out *o, const void *p, size_t n)
{
    if (o->err) return false;
    errno = 0;
    if (fwrite(p, 1, n, o->f) != n) {
        o->err = errno ? errno : EIO;
        return false;
    }
    return true;
}

om_status om_out_failed(const om_out *o, om_diag *d)
{
    return o->err ? fail(d, o->path, "cannot write", o->err) : OM_OK;
}

/* Flushes, syncs and closes (stdout stays open). A pipe or a terminal cannot be
 * synced (EINVAL, ENOTSUP): that is no error. */
static bool finish(om_out *o)
{
    errno = 0;
    if (!o->err && fflush(o->f) != 0) o->err = errno ? errno : EIO;
    if (!o->err && ferror(o->f)) o->err = EIO;
    if (!o->err && fsync(fileno(o->f)) != 0 && errno != EINVAL && errno != ENOTSUP &&
        errno != EROFS)
        o->err = errno;
    if (!o->is_stdout && fclose(o->f) != 0 && !o->err) o->err = errno ? errno : EIO;
    o->f = NULL;
    return !o->err;
}


void om_out_discard(om_out *o)
{
    if (o->f && !o->is_stdout) fclose(o->f);
    o->f = NULL;
    if (o->tmp) {
        live_remove(o->tmp);
        unlink(o->tmp);
    }
    free(o->tmp);
    free(o->target);
    o->tmp = o->target = NULL;
}

/* The directory of a target, opened for its lock (-1 where it cannot be). */
static int dir_fd(const char *target, struct stat *sb)
{
    const char *slash = strrchr(target, '/');
    char *dir = slash ? malloc((size_t)(slash - target) + 2) : NULL;
    if (slash && !dir) return -1;
    if (dir) {
        memcpy(dir, target, (size_t)(slash - target) + 1);
        dir[slash - target + 1] = '\0';
    }
    int fd = open(dir ? dir : ".", O_RDONLY);
    free(dir);
    if (fd >= 0 && fstat(fd, sb) != 0) {
        close(fd);
        fd = -1;
    }
    return fd;
}

/* The rename is durable once the directory is synced too; a system that cannot sync
 * a directory still has the file whole, old or new. */
static void sync_dir(const char *target)
{
    struct stat sb;
    const int fd = dir_fd(target, &sb);
    if (fd >= 0) {
        fsync(fd);
        close(fd);
    }
}

/* Locks the directories of the commit's renames, each once, in the order of their
 * device and inode numbers (so two commits never wait on each other crosswise);
 * returns how many of fds[] it holds. A directory that cannot be locked is left
 * unlocked: the renames are each atomic still. */
#define LOCK_MAX 8
static size_t lock_dirs(om_out *const *outs, size_t n, int *fds)
{
    struct stat sb[LOCK_MAX];
    size_t k = 0;
    for (size_t i = 0; i < n && k < LOCK_MAX; i++) {
        if (!outs[i] || !outs[i]->tmp) continue;
        struct stat st;
        const int fd = dir_fd(outs[i]->target, &st);
        if (fd < 0) continue;
        size_t j = 0;
        while (j < k && !(sb[j].st_dev == st.st_dev && sb[j].st_ino == st.st_ino)) j++;
        if (j < k) { close(fd); continue; }
        for (j = k; j > 0 && (sb[j - 1].st_dev > st.st_dev ||
                              (sb[j - 1].st_dev == st.st_dev && sb[j - 1].st_ino > st.st_ino)); j--) {
            sb[j] = sb[j - 1];
            fds[j] = fds[j - 1];
        }
        sb[j] = st;
        fds[j] = fd;
        k++;
    }
    for (size_t j = 0; j < k; j++)
        while (flock(fds[j], LOCK_EX) != 0 && errno == EINTR) {}
    return k;
}

om_status om_out_commit(om_out *const *outs, size_t n, om_diag *d)
{
    om_status st = OM_OK;
    for (size_t i = 0; i < n; i++) {
        om_out *o = outs[i];
        if (!o || !o->f) continue;
        if (!finish(o) && st == OM_OK) st = fail(d, o->path, "cannot write", o->err);
    }
    sigset_t hold, old;
    sigemptyset(&hold);
    sigaddset(&hold, SIGINT);
    sigaddset(&hold, SIGTERM);
    sigaddset(&hold, SIGHUP);
    sigaddset(&hold, SIGXFSZ);
    sigprocmask(SIG_BLOCK, &hold, &old);
    int fds[LOCK_MAX];
    const size_t locked = st == OM_OK ? lock_dirs(outs, n, fds) : 0;
    for (size_t i = 0; i < n && st == OM_OK; i++) {
        om_out *o = outs[i];
        if (!o || !o->tmp) continue;
        if (rename(o->tmp, o->target) != 0) { st = fail(d, o->path, "cannot replace", errno); break; }
        sync_dir(o->target);
        live_remove(o->tmp);
        free(o->tmp);
        o->tmp = NULL;
    }
    for (size_t j = 0; j < locked; j++) close(fds[j]);   /* (closing unlocks) */
    for (size_t i = 0; i < n; i++)
        if (outs[i]) om_out_discard(outs[i]);
    sigprocmask(SIG_SETMASK, &old, NULL);
    return st;
}

/* ------------------------------------------------------------ names */

static bool is_null(const char *p)
{
    struct stat sp, sn;
    return stat(p, &sp) == 0 && stat("/dev/null", &sn) == 0 && sp.st_dev == sn.st_dev &&
           sp.st_ino == sn.st_ino;
}

bool om_out_same(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!strcmp(a, "-")) a = "/dev/stdout";
    if (!strcmp(b, "-")) b = "/dev/stdout";
    if (is_null(a)) return false;
    if (!strcmp(a, b)) return true;
    if (stat(a, &sa) == 0 && stat(b, &sb) == 0)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    /* Not both there yet: the same directory and the same last name. */
    char *ta = target_of(a), *tb = target_of(b);
    bool same = false;
    if (ta && tb) {
        const char *na = strrchr(ta, '/'), *nb = strrchr(tb, '/');
        na = na ? na + 1 : ta;
        nb = nb ? nb + 1 : tb;
        if (!strcmp(na, nb)) {
            char *da = dup_str(ta), *db = dup_str(tb);
            if (da && db) {
                da[na - ta] = '\0';
                db[nb - tb] = '\0';
                same = stat(da[0] ? da : ".", &sa) == 0 && stat(db[0] ? db : ".", &sb) == 0 &&
                       sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
            }
            free(da);
            free(db);
        }
    }
    free(ta);
    free(tb);
    return same;
}
