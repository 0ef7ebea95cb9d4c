/*
 * A QEMU TCG plugin that counts the guest instructions a user-mode program executes (all
 * threads), written when the program exits as "insns N" to $INSN_OUT (default: stderr).
 *
 * Used by bench/pi/budget.py to count each frame stage's instructions on the Pis' instruction
 * sets. Hand-written against QEMU's plugin API version 1 (QEMU 7.2, Debian 12's qemu-user),
 * declaring the five functions it calls: Debian ships qemu-user with plugin support but
 * neither its example plugins nor `qemu-plugin.h`, and a header from a newer QEMU declares a
 * newer API version that 7.2 refuses to load.
 *
 *     gcc -shared -fPIC -O2 -o libinsn.so insn.c
 *     INSN_OUT=count.txt qemu-aarch64 -cpu cortex-a76 -plugin ./libinsn.so PROGRAM ARGS
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb;
typedef struct qemu_info_t qemu_info_t;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS };
typedef void (*tb_trans_cb)(qemu_plugin_id_t, struct qemu_plugin_tb *);
typedef void (*udata_cb)(qemu_plugin_id_t, void *);
typedef void (*vcpu_udata_cb)(unsigned int, void *);

extern void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t, tb_trans_cb);
extern size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *);
extern void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *, vcpu_udata_cb,
                                                 enum qemu_plugin_cb_flags, void *);
extern void qemu_plugin_register_atexit_cb(qemu_plugin_id_t, udata_cb, void *);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

/* One counter for every thread, added to atomically (user-mode threads run in parallel). */
static uint64_t count;

static void on_exec(unsigned int vcpu, void *n_insns)
{
    (void)vcpu;
    __atomic_fetch_add(&count, (uint64_t)(uintptr_t)n_insns, __ATOMIC_RELAXED);
}

/* Every translated block adds its instruction count each time it executes. */
static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    qemu_plugin_register_vcpu_tb_exec_cb(tb, on_exec, QEMU_PLUGIN_CB_NO_REGS,
                                         (void *)(uintptr_t)qemu_plugin_tb_n_insns(tb));
}

static void at_exit(qemu_plugin_id_t id, void *unused)
{
    (void)id;
    (void)unused;
    const char *path = getenv("INSN_OUT");
    FILE *f = fopen(path ? path : "/dev/stderr", "a");
    if (f) {
        fprintf(f, "insns %llu\n", (unsigned long long)count);
        fclose(f);
    }
}

__attribute__((visibility("default"))) int
qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    (void)info;
    (void)argc;
    (void)argv;
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
