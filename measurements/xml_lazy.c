/* The libxml2 functions the RSML reader and writer call
 * (measurements/rsml.c), forwarded to libxml2 opened on first use
 * (measurements/lazy_library_internal.h; phc_rsml_read and phc_rsml_write open it
 * first and report when they cannot): a run without RSML files never loads
 * libxml2, ICU or lzma.  Prototypes: libxml2's headers. */
#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlstring.h>
#include <libxml/xmlwriter.h>

#include "measurements/lazy_library_internal.h"

#define L phc_lazy_xml

PHC_LAZY_FORWARD(L, int, xmlCheckUTF8, (const unsigned char *utf), (utf))
PHC_LAZY_FORWARD(L, xmlDocPtr, xmlCtxtReadFile,
                 (xmlParserCtxtPtr ctxt, const char *filename, const char *encoding, int options),
                 (ctxt, filename, encoding, options))
PHC_LAZY_FORWARD(L, xmlNodePtr, xmlDocGetRootElement, (const xmlDoc *doc), (doc))
PHC_LAZY_FORWARD_VOID(L, xmlFreeDoc, (xmlDocPtr cur), (cur))
PHC_LAZY_FORWARD_VOID(L, xmlFreeParserCtxt, (xmlParserCtxtPtr ctxt), (ctxt))
PHC_LAZY_FORWARD_VOID(L, xmlFreeTextWriter, (xmlTextWriterPtr writer), (writer))
PHC_LAZY_FORWARD(L, long, xmlGetLineNo, (const xmlNode *node), (node))
PHC_LAZY_FORWARD_VOID(L, xmlInitParser, (void), ())
PHC_LAZY_FORWARD(L, xmlParserCtxtPtr, xmlNewParserCtxt, (void), ())
PHC_LAZY_FORWARD(L, xmlTextWriterPtr, xmlNewTextWriter, (xmlOutputBufferPtr out), (out))
PHC_LAZY_FORWARD(L, xmlChar *, xmlNodeGetContent, (const xmlNode *cur), (cur))
PHC_LAZY_FORWARD(L, xmlChar *, xmlNodeListGetString, (xmlDocPtr doc, const xmlNode *list, int inLine),
                 (doc, list, inLine))
PHC_LAZY_FORWARD(L, int, xmlOutputBufferClose, (xmlOutputBufferPtr out), (out))
PHC_LAZY_FORWARD(L, xmlOutputBufferPtr, xmlOutputBufferCreateFile, (FILE *file, xmlCharEncodingHandlerPtr encoder),
                 (file, encoder))
PHC_LAZY_FORWARD(L, int, xmlTextWriterEndDocument, (xmlTextWriterPtr writer), (writer))
PHC_LAZY_FORWARD(L, int, xmlTextWriterEndElement, (xmlTextWriterPtr writer), (writer))
PHC_LAZY_FORWARD(L, int, xmlTextWriterSetIndent, (xmlTextWriterPtr writer, int indent), (writer, indent))
PHC_LAZY_FORWARD(L, int, xmlTextWriterSetIndentString, (xmlTextWriterPtr writer, const xmlChar *str),
                 (writer, str))
PHC_LAZY_FORWARD(L, int, xmlTextWriterStartDocument,
                 (xmlTextWriterPtr writer, const char *version, const char *encoding, const char *standalone),
                 (writer, version, encoding, standalone))
PHC_LAZY_FORWARD(L, int, xmlTextWriterStartElement, (xmlTextWriterPtr writer, const xmlChar *name),
                 (writer, name))
PHC_LAZY_FORWARD(L, int, xmlTextWriterWriteAttribute,
                 (xmlTextWriterPtr writer, const xmlChar *name, const xmlChar *content),
                 (writer, name, content))
PHC_LAZY_FORWARD(L, int, xmlTextWriterWriteElement,
                 (xmlTextWriterPtr writer, const xmlChar *name, const xmlChar *content),
                 (writer, name, content))

/* xmlFree is a variable of libxml2 (a pointer to its deallocator), read by
 * rsml.c as xmlFree(p): this one calls the library's. */
static void xml_free_forward(void *p)
{
    static _Atomic(void *) slot;
    xmlFreeFunc *real = phc_lazy_library_function(&L, "xmlFree", &slot);
    (*real)(p);
}
xmlFreeFunc xmlFree = xml_free_forward;
