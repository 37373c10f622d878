/* The run ledger of a long study: an append-only text file with one line
 * per finished model evaluation, written in small batches as results
 * arrive (below), so that an interrupted study continues (`--resume`)
 * without recomputing anything the ledger holds.
 *
 * Format (tab-separated, one record per line):
 *   # phytocal run ledger 2
 *   @ KEY VALUE            the study's identity (config SHA-256, method,
 *   ...                    samples, seed, design, parameters and their
 *   @ end                  priors, outputs): resume refuses any difference
 *   ROW STATE V1 .. VK #C  ROW = design row, STATE = ok | failed, the K
 *                          outputs each as the 16 lower-case hex digits of
 *                          its IEEE-754 binary64 bit pattern, most
 *                          significant first (exact; NaN when failed),
 *                          C = the 8 hex digits of the CRC-32C (Castagnoli,
 *                          as iSCSI) of the line before " #"
 * The CRC detects torn and altered lines (any burst of up to 32 bits, all
 * but 2^-32 of other changes); it is no defence against deliberate
 * tampering, which the ledger never promised.  Format 1 (earlier phytocal:
 * outputs as %.17g, C = the first 16 hex digits of the line's SHA-256) is
 * still read, and a resumed format-1 ledger is appended to in format 1; a
 * newer format is refused with its number.
 * A last line without its newline (the process died while writing it) is
 * cut off on resume; any other line that does not parse or whose checksum
 * does not match is an error naming the file and line.  Records go to the
 * operating system in batches, one write(2) each: a batch is written when
 * it holds 64 records or 64 KiB, when a record arrives 50 ms or more after
 * the last write (so a study whose evaluations take 50 ms or more writes
 * every record as it comes), and at phc_run_ledger_close (also when a study
 * stops on an error or is cancelled).  A process that is killed (SIGKILL)
 * loses at most the records of the batch not yet written: at most 63
 * records, all appended less than 50 ms after the last write; they are
 * recomputed on --resume.  Not fsync: a machine that loses power may lose
 * the last lines too. */
#ifndef PHC_RUN_LEDGER_H
#define PHC_RUN_LEDGER_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_run_ledger phc_run_ledger;

enum { PHC_LEDGER_PENDING = 0, PHC_LEDGER_OK = 1, PHC_LEDGER_FAILED = 2 };

/* Opens the ledger at path for a study of `rows` evaluations of n_out
 * outputs, identified by n_keys KEY / VALUE pairs (no tabs or newlines).
 * resume = 0: creates it (PHC_ERR_EXISTS when the file exists, unless
 * replace); resume = 1: reads it (PHC_ERR_INPUT when absent, when a KEY
 * differs: "PATH: the ledger is from another study: KEY is 'A' there and
 * 'B' now", or when a line is corrupt), fills y (rows x n_out) and state
 * (rows) with what it holds, and appends after it. */
int phc_run_ledger_open(const char *path, const char *const *keys, const char *const *values, size_t n_keys,
                        size_t rows, size_t n_out, int resume, int replace, double *y, unsigned char *state,
                        size_t *n_found, phc_run_ledger **out, phc_error *err);
/* Appends row's outputs (failed: state failed, outputs written as nan) and
 * flushes. */
int phc_run_ledger_append(phc_run_ledger *l, size_t row, int failed, const double *y, phc_error *err);
/* Closes (accepts NULL); PHC_ERR_IO when the last writes failed. */
int phc_run_ledger_close(phc_run_ledger *l, phc_error *err);

#endif /* PHC_RUN_LEDGER_H */
