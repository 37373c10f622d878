/* BAAD study folders: the Biomass And Allometry Database (Falster et al.
 * 2015, Ecology 96:1445; data CC0, github.com/dfalster/baad).
 *
 * A study folder (e.g. baad/Baltzer2007/) holds
 *   data.csv              the contributor's raw table, raw column names;
 *   dataMatchColumns.csv  var_in (raw column), unit_in, var_out (BAAD
 *                         variable; NA = not used), one line per raw column;
 *   dataNew.csv           corrections: lookupVariable/lookupValue select rows
 *                         whose newVariable becomes newValue ("species" "QR"
 *                         -> "Quercus rubra"); an empty or NA lookupVariable
 *                         sets newVariable in every row (site coordinates,
 *                         defaults such as h.bh = 1.3 m); optional;
 *   dataManipulate.R      R code BAAD's build runs on data.csv before the
 *                         mapping (new columns, fixes); NOT run here;
 *   studyMetadata.csv     prose (not read here);
 * and the folder's parent holds BAAD's config/ folder (config/
 * variableDefinitions.csv: each BAAD variable with its type and canonical
 * unit; config/variableConversion.csv: unit_in, unit_out and the R
 * expression in x that converts, e.g. "g,kg,x/1000", "m2/kg,kg/m2,1/x").
 * For small hand-made trees, a variableDefinitions.csv (and
 * variableConversion.csv) directly in the parent is used when config/ has
 * none.
 *
 * What phc_baad_read does, in this order (as BAAD's own build,
 * dfalster/baad R/build.R, for the variables it reads):
 *  1. maps every raw column with a var_out to its BAAD variable.  A mapping
 *     row whose var_in is not a column of data.csv (a column the study's
 *     dataManipulate.R creates) is skipped with a warning
 *     (phc_baad_warnings), never an error.  Numeric variables are converted
 *     from unit_in to the canonical unit by the expression of the
 *     variableConversion.csv row (unit_in, canonical unit): x/1000, 1/x,
 *     10/x, x*10^-6 ... (+ - * / ^, parentheses, numbers and x); equal units
 *     need none; a pair the file does not define is an error naming
 *     dataMatchColumns.csv's line and variableConversion.csv.  Without any
 *     variableConversion.csv, units are converted with UDUNITS-2 instead
 *     (mm -> m, months -> yr; BAAD's "deg" means arc degrees, or degrees
 *     Celsius for mat).  Empty cells, "NA" and, in numeric columns, a lone
 *     "-" (a dash for "not measured", as in Baltzer2007 data.csv:398) are
 *     absent (NAN).  Text values (species, growingCondition ...) are
 *     trimmed of leading and trailing blanks ("Acer rubrum " -> "Acer
 *     rubrum"), and so are dataNew's lookup and new values;
 *  2. site coordinates: a mapped latitude/longitude column, or else an
 *     unmapped raw column named Lat/Latitude and Long/Lon/Longitude (any
 *     case), is parsed with phc_geo_parse_angle ("43.6481 N", "79.4042 W",
 *     "-79.4"); these are the raw coordinates;
 *  3. applies dataNew.csv row by row, in file order.  New values of numeric
 *     variables are in the canonical unit (BAAD's convention: dataNew is
 *     applied to standardised data; h.bh = 1.3 is metres).  When dataNew sets
 *     latitude or longitude, the geodesic distance between the raw and the
 *     corrected site is kept (phc_baad_site_shift);
 *  4. derives, per row and only where the variable is absent: the basal
 *     diameter from the stem area at base, d.ba = 2 sqrt(a.stba / pi) (both
 *     in BAAD's canonical m and m2); the root mass m.rt = m.rf + m.rc (fine
 *     and coarse roots, variableDefinitions: "total root mass
 *     (=m.rf+m.rc)"); the shoot mass m.so = m.st + m.lf; then the
 *     root:shoot ratio m.rt/m.so;
 *  5. flags rows, never drops them (see phc_baad_flag below).
 *
 * Units of the row fields: d_ba, h_t in m; masses in kg; age in yr;
 * latitude, longitude in degrees (north, east positive).
 *
 * Errors (PHC_ERR_INPUT unless said otherwise) name the file, its line and
 * the value: a conversion variableConversion.csv does not define (or an
 * unknown unit without it), a conversion expression that cannot be read, a
 * var_out or newVariable that variableDefinitions.csv does not define, a
 * numeric variable without unit_in, a non-number in a mapped numeric column
 * (data.csv, line and column), a malformed latitude/longitude, a dataNew
 * lookupVariable that names no variable.  A folder without
 * dataMatchColumns.csv is PHC_ERR_IO naming the path ("not a BAAD study
 * folder"); so is a missing or unreadable data.csv or variableDefinitions.csv.
 * The library never prints: reports print the warnings, the counts, the
 * flags, the dataNew change counts and the site shift. */
#ifndef PHC_BAAD_H
#define PHC_BAAD_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Kinds of flagged rows (phc_baad_row.flag). */
enum phc_baad_flag {
    PHC_BAAD_OK = 0,
    /* Plausible numbers that disagree with the row's peers, by one of two
     * robust rules (each needs >= PHC_BAAD_MIN_GROUP rows; spread s =
     * max(1.4826 * MAD, PHC_BAAD_SPREAD_FLOOR), in natural-log units):
     *  - diameter: |log d.ba - median log d.ba| > PHC_BAAD_ROBUST_Z * s
     *    within the rows of the same species and the same age;
     *  - allometry: the residual of log m.so about the species' Theil-Sen
     *    line log m.so = a + b log d.ba exceeds PHC_BAAD_ROBUST_Z * s of the
     *    species' residuals.
     * A diameter far from its age group but in line with the plant's own
     * mass (allometry |z| <= PHC_BAAD_CONSISTENT_Z) is a large or small
     * plant, not a typo, and is not flagged (Baltzer2007 data.csv:531, an
     * Ulmus americana of 8.53 mm and 4.8 g shoot among 1.3 mm peers). */
    PHC_BAAD_SUSPICIOUS = 1,
    /* A mass, diameter or height that is zero, negative or not finite: the
     * row's values are kept as read but take no part in the peer rules. */
    PHC_BAAD_INVALID = 2
};

#define PHC_BAAD_MIN_GROUP 5
#define PHC_BAAD_ROBUST_Z 5.0
#define PHC_BAAD_SPREAD_FLOOR 0.1 /* natural-log units (~10 %) */
#define PHC_BAAD_CONSISTENT_Z 2.0

typedef struct phc_baad_row {
    size_t line;                   /* line in data.csv (1-based, header is line 1) */
    const char *species;           /* after dataNew mapping (points into the study's
                                      storage), NULL when absent */
    double age;                    /* yr, NAN when absent */
    double d_ba, h_t;              /* basal diameter, total height: m, NAN when absent */
    double m_rt, m_st, m_lf, m_so; /* root, stem, leaf, above-ground (shoot) mass: kg,
                                      NAN when absent; m_so derived as above */
    double latitude, longitude;    /* degrees, NAN when absent (after dataNew) */
    const char *growing_condition; /* BAAD growingCondition code (GH, FW ...) or NULL */
    int flag;                      /* PHC_BAAD_OK, PHC_BAAD_SUSPICIOUS, PHC_BAAD_INVALID */
    const char *flag_reason;       /* NULL when ok; one sentence naming the values,
                                      the peer group and the rule */
    /* additions */
    double root_shoot;             /* m_rt / m_so (dimensionless), NAN unless both present */
    int m_so_derived;              /* 1 when m_so was computed as m_st + m_lf */
    int m_rt_derived;              /* 1 when m_rt was computed as m_rf + m_rc */
    int d_ba_derived;              /* 1 when d_ba was computed from a.stba */
} phc_baad_row;

typedef struct phc_baad_study phc_baad_study; /* opaque */

/* What reading a study did, for reports (phc_baad_count). */
typedef struct phc_baad_counts {
    size_t conversions;       /* mapped numeric columns converted to BAAD's unit */
    size_t skipped_mappings;  /* mapping rows skipped: var_in not a column of data.csv */
    size_t trimmed;           /* text cells trimmed of blanks (data.csv and dataNew.csv) */
    size_t not_numbers;       /* cells of mapped numeric columns read as absent: not numbers
                                 (or unreadable coordinates) */
    size_t derived_diameters; /* rows whose d.ba comes from a.stba */
    size_t derived_roots;     /* rows whose m.rt is m.rf + m.rc */
    size_t derived_shoots;    /* rows whose m.so is m.st + m.lf */
    size_t ages;              /* rows with an age */
} phc_baad_counts;

/* Reads the study folder `study_dir` (BAAD's config files are taken from
 * its parent folder's config/, else from the parent itself).  On success
 * *out owns everything; free with phc_baad_free.  On failure *out is NULL
 * and err says where and why. */
int phc_baad_read(const char *study_dir, phc_baad_study **out, phc_error *err);
void phc_baad_free(phc_baad_study *s); /* accepts NULL */

const char *phc_baad_name(const phc_baad_study *s); /* folder name, e.g. "Baltzer2007" */
/* The files the study was read from, as opened (dataImportOptions.csv when
 * present, data.csv, dataMatchColumns.csv, dataNew.csv when present,
 * ../config/variableDefinitions.csv and ../config/variableConversion.csv, or
 * the parent's own copies), for provenance; *paths (may be NULL) points into
 * the study. */
size_t phc_baad_inputs(const phc_baad_study *s, const char *const **paths);
size_t phc_baad_rows(const phc_baad_study *s);
const phc_baad_row *phc_baad_row_at(const phc_baad_study *s, size_t i); /* NULL if i is out of range */

/* Raw text (trimmed, unquoted) of row i's cell in the data.csv column named
 * raw_column (exact name), e.g. "Light"; NULL when there is no such column
 * or i is out of range. */
const char *phc_baad_raw(const phc_baad_study *s, size_t i, const char *raw_column);

/* Distinct species in file order; *names (may be NULL) points into the
 * study and stays valid until phc_baad_free.  Rows without a species are
 * not counted. */
size_t phc_baad_species(const phc_baad_study *s, const char ***names);

/* Geodesic distance (m, WGS84) between the raw site coordinates and the ones
 * dataNew.csv gives, the largest over rows that have both; NAN when dataNew
 * sets no coordinate or no row has raw coordinates. */
double phc_baad_site_shift(const phc_baad_study *s);

/* Any BAAD variable of the study (mapped from data.csv or set by dataNew),
 * by its BAAD name ("a.lf", "ma.ilf", "h.bh" ...).  phc_baad_value: the
 * number in phc_baad_unit's unit, NAN when absent, not numeric or unknown;
 * phc_baad_text: the text after dataNew (the raw cell for mapped columns),
 * NULL when absent ("NA" or empty) or unknown. */
double phc_baad_value(const phc_baad_study *s, size_t i, const char *variable);
const char *phc_baad_text(const phc_baad_study *s, size_t i, const char *variable);
/* Canonical unit of a numeric variable ("m", "kg", "yr", "m2", "kg/m2",
 * "deg" ...; BAAD's spelling), NULL for character or unknown variables. */
const char *phc_baad_unit(const phc_baad_study *s, const char *variable);

/* One applied dataNew.csv line and how many rows it touched. */
typedef struct phc_baad_change {
    size_t line;                  /* line in dataNew.csv */
    const char *lookup_variable;  /* NULL for "all rows" */
    const char *lookup_value;     /* NULL for "all rows" or NA */
    const char *new_variable;
    const char *new_value;        /* NULL for NA */
    size_t rows_matched;          /* rows selected by the lookup */
    size_t rows_changed;          /* of those, rows whose value differed before */
} phc_baad_change;

/* The dataNew.csv lines in file order; *changes (may be NULL) points into
 * the study. */
size_t phc_baad_changes(const phc_baad_study *s, const phc_baad_change **changes);

/* The counts above (all 0 for NULL). */
phc_baad_counts phc_baad_count(const phc_baad_study *s);

/* Warnings in file order, one sentence each, naming the file and line:
 * "Abe1981/dataMatchColumns.csv:7: var_in 'x' (var_out m.rt) is not a
 * column of data.csv (the study's dataManipulate.R makes it; not run
 * here): mapping skipped".  *warnings (may be NULL) points into the study. */
size_t phc_baad_warnings(const phc_baad_study *s, const char *const **warnings);

/* Why the study cannot give root:shoot data, as one sentence naming what is
 * missing ("no root mass: no column is mapped to m.rt (nor to both m.rf and
 * m.rc)"; likewise shoot mass m.so / m.st and m.lf, and basal diameter d.ba /
 * a.stba), or NULL when the variables exist (their rows may still be
 * empty). */
const char *phc_baad_lacks(const phc_baad_study *s);

/* Number of rows with the given flag value. */
size_t phc_baad_flagged(const phc_baad_study *s, int flag);

#ifdef __cplusplus
}
#endif

#endif /* PHC_BAAD_H */
