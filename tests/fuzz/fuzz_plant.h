/* The plant-graph harnesses (fuzz_plant_<format>.c): the input is a file in
 * one format, read with that format given explicitly (measurements/plant_io.h).
 * A graph that reads is written in phytocal's native CSV and read back, which
 * must succeed with the same segment count: the writer's output is valid
 * input.  The paper harness also writes the paper format. */
#ifndef PHC_FUZZ_PLANT_H
#define PHC_FUZZ_PLANT_H

#include "fuzz_common.h"

#include "measurements/plant_io.h"

static int phc_fuzz_plant(const uint8_t *data, size_t size, phc_plant_format format,
                          const char *file_name)
{
    char path[4200], out[4200];
    phc_error err;
    phc_plant_graph *g = NULL, *back = NULL;
    phc_fuzz_clear();
    phc_fuzz_write(file_name, data, size, path, sizeof path);
    int rc = phc_plant_io_read(path, format, 0, &g, &err);
    phc_fuzz_check_error(rc, &err, file_name);
    if (rc != 0) {
        if (g)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        return 0;
    }
    snprintf(out, sizeof out, "%s/written.csv", phc_fuzz_dir());
    if (phc_plant_io_write_native(out, g, &err) != 0)
        phc_fuzz_fail("a graph that was read cannot be written", err.message);
    if (phc_plant_io_read(out, PHC_PLANT_FORMAT_NATIVE, 0, &back, &err) != 0)
        phc_fuzz_fail("the native file the writer wrote does not read back", err.message);
    if (back->n != g->n)
        phc_fuzz_fail("the native file the writer wrote reads back with another size", NULL);
    if (format == PHC_PLANT_FORMAT_PAPER) {
        snprintf(out, sizeof out, "%s/written.txt", phc_fuzz_dir());
        phc_plant_io_write_paper(out, g, &err);
    }
    phc_plant_graph_free(back);
    phc_plant_graph_free(g);
    return 0;
}

#endif /* PHC_FUZZ_PLANT_H */
