/* Status codes and error messages (model/status.h): phc_error_set and
 * phc_error_prefix, including a prefix that overflows the message. */
#include <string.h>

#include "check.h"
#include "model/status.h"

int main(void)
{
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_error_set(&err, PHC_ERR_INPUT, "leaf %d not found", 3) == PHC_ERR_INPUT);
    CHECK(phc_error_prefix(&err, PHC_ERR_IO, "%s:%d", "photos.csv", 4) == PHC_ERR_IO);
    CHECK(err.status == PHC_ERR_IO);
    CHECK(strcmp(err.message, "photos.csv:4: leaf 3 not found") == 0);
    /* prefixes stack, outermost first */
    phc_error_prefix(&err, PHC_ERR_IO, "cfg.yaml:7");
    CHECK(strcmp(err.message, "cfg.yaml:7: photos.csv:4: leaf 3 not found") == 0);
    /* a NULL error still returns the status */
    CHECK(phc_error_prefix(NULL, PHC_ERR_INPUT, "x") == PHC_ERR_INPUT);
    /* too long: truncated, terminated, the place kept whole */
    char place[PHC_ERROR_MESSAGE_SIZE - 10];
    memset(place, 'p', sizeof place - 1);
    place[sizeof place - 1] = '\0';
    phc_error_set(&err, PHC_ERR_INPUT, "the reason");
    phc_error_prefix(&err, PHC_ERR_INPUT, "%s", place);
    CHECK(strlen(err.message) == PHC_ERROR_MESSAGE_SIZE - 1);
    CHECK(strncmp(err.message, place, strlen(place)) == 0);
    CHECK(strncmp(err.message + strlen(place), ": the", 5) == 0);
    /* a message is one line: control characters quoted from the input are
     * escaped (a fuzzing find: a quoted CSV header with a line break) */
    phc_error_set(&err, PHC_ERR_INPUT, "column '%s'", "y\nz\t\x7f\r");
    CHECK(strcmp(err.message, "column 'y\\nz\\t\\x7f\\r'") == 0);
    phc_error_set(&err, PHC_ERR_INPUT, "reason");
    phc_error_prefix(&err, PHC_ERR_INPUT, "a\nb");
    CHECK(strcmp(err.message, "a\\nb: reason") == 0);
    /* escapes that do not fit are dropped whole, never cut */
    char longer[PHC_ERROR_MESSAGE_SIZE];
    memset(longer, 'p', PHC_ERROR_MESSAGE_SIZE - 4);
    longer[PHC_ERROR_MESSAGE_SIZE - 4] = '\x01'; /* its escape needs 4 of the 3 bytes left */
    longer[PHC_ERROR_MESSAGE_SIZE - 3] = '\0';
    phc_error_set(&err, PHC_ERR_INPUT, "%s", longer);
    CHECK(strlen(err.message) == PHC_ERROR_MESSAGE_SIZE - 4);
    CHECK(strchr(err.message, '\\') == NULL);
    return check_finish("test_status");
}
