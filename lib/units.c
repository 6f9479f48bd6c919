/* units.c: quantities with units at the edges (see towstab/units.h).
 *
 * Algorithm. A quantity is "<number> [<unit>]". The number is scanned by a
 * small decimal grammar of our own ([+-] digits [. digits] [e [+-] digits];
 * no hex floats, no NaN, no infinities, no YAML specials like ".inf"), then
 * converted by strtod on exactly that lexeme. The unit text is parsed by
 * udunits2 (ut_parse, ASCII) and converted to the SI unit the caller asks
 * for with a udunits converter. No unit means SI.
 *
 * Dimensions are compared with ut_are_convertible. udunits treats radians
 * as dimensionless, so on its own it would convert "1 Hz" to "1 rad/s" and
 * "2 rad" to "2" (a factor 2 pi or a degree/radian mix-up waiting to
 * happen); we therefore also require the ratio of the two units to carry no
 * radian (its udunits definition must not mention "rad"). Offset units
 * (degC, timestamps "s since ...") are refused: every quantity here is a
 * plain scale of its SI unit.
 *
 * Messages name the dimension in words for the common cases (length, mass,
 * force, speed, force per length, ...) and recognise the mass-versus-force
 * confusion ("50 lb" where a weight in N is expected; "1 lb/ft" where N/m is
 * expected) with a concrete suggestion ("50 lbf").
 *
 * Aliases added to the database at load time (udunits lacks them or reads
 * them as something else): kn -> knot, deg -> degree, lbs -> lb,
 * nmi -> nautical_mile (udunits reads "nmi" as nano-mile), mph -> mile/hour
 * (udunits reads "mph" as milli-phot), and slug redefined exactly as
 * lbf s^2/ft (udunits rounds it to 14.5939 kg, 2e-7 off).
 *
 * Start-up: a bare number needs no unit system; a unit whose words are all
 * among the common ones below is read in a small system built in memory
 * (no XML); any other unit in udunits2's whole XML database, read on first
 * need. Each is made once per ts_units, when first needed.
 *
 * Thread safety: udunits' parser (ut_parse) keeps global state and its
 * error handler is process-wide, and a ts_units makes its systems on first
 * use, so ts_units_parse and ts_units_from_si must not run concurrently in
 * several threads, even on distinct ts_units.
 */
#include "towstab/units.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <udunits2.h>

#include "units_impl.h"

/* The unit systems, read when a quantity first needs one. */
typedef struct units_db {
    ut_system *small; /* the units of the table below; NULL until needed */
    ut_system *full;  /* udunits2's whole XML database; NULL until needed */
} units_db;

struct ts_units {
    units_db *db; /* owned; the systems are filled in on first use */
};

/* Longest unit text and number lexeme we accept (a scene value longer than
 * this is certainly a mistake, and fixed buffers keep the code simple). */
#define UNIT_TEXT_MAX 128
#define NUMBER_TEXT_MAX 64
/* Longest excerpt of user text quoted in a message. */
#define QUOTE_MAX 60

/* ------------------------------------------------------------------ */
/* The small system                                                     */

/* The units most scenes and options use, built in memory with udunits'
 * own calls instead of read from its XML database (reading the XML, about
 * 280 units and their prefixes, costs a run about 2 ms: doc/performance.md,
 * "Start-up"). Each definition is udunits2's own (udunits2-base, -derived,
 * -accepted and -common.xml), parsed by udunits in this system, so a unit
 * here converts exactly as in the whole database; test_units checks every
 * word below against the whole database, bit for bit. A unit text is
 * converted in this system only when each of its words (letters and '_')
 * is one of these names, plurals, symbols or prefixed words; any other
 * word sends the whole conversion to the whole database, so every unit
 * udunits2 knows still works, with the same messages. */
static const struct {
    const char *name, *plural, *symbol, *symbol2, *definition;
} small_units[] = {
    /* Derived and accepted (base units and the radian are made below). */
    {"hertz", "hertz", "Hz", NULL, "1/s"},
    {"gram", "grams", "g", NULL, "1e-3 kg"},
    {"newton", "newtons", "N", NULL, "m.kg/s^2"},
    {"pascal", "pascals", "Pa", NULL, "N/m^2"},
    {"joule", "joules", "J", NULL, "N.m"},
    {"watt", "watts", "W", NULL, "J/s"},
    {"minute", "minutes", "min", NULL, "60 s"},
    {"hour", "hours", "h", "hr", "60 min"},
    {"pi", NULL, NULL, NULL, "3.141592653589793238462643383279"},
    {"degree", "degrees", NULL, NULL, "(pi/180) rad"},
    {"nautical_mile", "nautical_miles", NULL, NULL, "1852 m"},
    {"knot", "knots", "kt", "kts", "nautical_mile/hour"},
    {"rotation", "rotations", NULL, NULL, "2 pi rad"},
    {NULL, NULL, "rpm", NULL, "rotation/minute"},
    {"pound", "pounds", "lb", NULL, "4.5359237e-1 kg"},
    {"inch", "inches", "in", NULL, "2.54 cm"},
    {"foot", "feet", "ft", NULL, "12 inches"},
    {"mile", "miles", NULL, NULL, "5280 feet"},
    {"standard_free_fall", NULL, NULL, NULL, "9.806650 m/s^2"},
    {"kilogram_force", "kilograms_force", "kgf", NULL, "9.806650 N"},
    {"pound_force", "pounds_force", "lbf", NULL, "4.4482216152605 N"},
};

/* Base units (name, plural, symbol) and the dimensionless radian. */
static const char *const small_base[][3] = {
    {"meter", "meters", "m"},    {"kilogram", "kilograms", "kg"},
    {"second", "seconds", "s"},  {"kelvin", "kelvins", "K"},
    {"radian", "radians", "rad"},
};

/* Words with an SI prefix the small system also takes (udunits resolves
 * them by prefix, as the whole database does). */
static const char *const small_prefixed[] = {
    "km", "cm", "mm", "um", "kN", "MN", "kPa", "MPa", "GPa", "kW", "MW",
    "ms", "mHz", "kHz", "mrad", "kilometer", "centimeter", "millimeter",
    "kilonewton", "millisecond",
};

/* SI prefixes of udunits2-prefixes.xml that the prefixed words use. */
static const struct {
    const char *name, *symbol;
    double value;
} small_prefix[] = {
    {"giga", "G", 1e9},  {"mega", "M", 1e6},  {"kilo", "k", 1e3},
    {"centi", "c", .01}, {"milli", "m", 1e-3}, {"micro", "u", 1e-6},
};

/* Aliases added to both systems (see the file's head). */
static const char *const alias[][2] = {
    {"kn", "knot"},
    {"deg", "degree"},
    {"lbs", "lb"},
    {"nmi", "nautical_mile"},
    {"mph", "mile/hour"},
};

/* Map `alias` as a symbol for the unit `definition`. */
static int add_alias(ut_system *sys, const char *alias, const char *definition,
                     ts_err *err)
{
    ut_unit *unit = ut_parse(sys, definition, UT_ASCII);
    if (!unit)
        return ts_fail(err, TS_EUNIT, "units: the unit database has no unit "
                       "'%s' (for alias '%s')", definition, alias);
    ut_status st = ut_map_symbol_to_unit(alias, UT_ASCII, unit);
    ut_free(unit);
    if (st != UT_SUCCESS)
        return ts_fail(err, TS_EUNIT, "units: cannot add the alias '%s' for "
                       "'%s' (udunits status %d)", alias, definition,
                       (int)st);
    return TS_OK;
}

/* Replace the name `name` (and its plural) by `definition`. */
static int redefine_name(ut_system *sys, const char *name, const char *plural,
                         const char *definition, ts_err *err)
{
    ut_unit *unit = ut_parse(sys, definition, UT_ASCII);
    if (!unit)
        return ts_fail(err, TS_EUNIT, "units: the unit database cannot read "
                       "'%s' (to define '%s')", definition, name);
    /* Unmapping a name that is not mapped is not an error. */
    ut_unmap_name_to_unit(sys, name, UT_ASCII);
    ut_unmap_name_to_unit(sys, plural, UT_ASCII);
    ut_status st = ut_map_name_to_unit(name, UT_ASCII, unit);
    if (st == UT_SUCCESS)
        st = ut_map_name_to_unit(plural, UT_ASCII, unit);
    ut_free(unit);
    if (st != UT_SUCCESS)
        return ts_fail(err, TS_EUNIT, "units: cannot redefine '%s' as '%s' "
                       "(udunits status %d)", name, definition, (int)st);
    return TS_OK;
}

/* towstab's additions to a system: the aliases and the exact slug. */
static int add_ours(ut_system *sys, ts_err *err)
{
    for (size_t i = 0; i < sizeof alias / sizeof alias[0]; i++)
        if (add_alias(sys, alias[i][0], alias[i][1], err) != TS_OK)
            return TS_EUNIT;
    return redefine_name(sys, "slug", "slugs", "lbf*s^2/ft", err);
}

/* Map the name, plural and symbols to `unit`; the base units' symbols
 * also the other way, so that a definition is written in them as the
 * whole database writes it ("m-1.kg"). UT_SUCCESS or udunits' status. */
static ut_status map_unit(ut_unit *unit, const char *name, const char *plural,
                          const char *symbol, const char *symbol2, int base)
{
    ut_status st = UT_SUCCESS;
    if (name)
        st = ut_map_name_to_unit(name, UT_ASCII, unit);
    if (st == UT_SUCCESS && plural && strcmp(plural, name) != 0)
        st = ut_map_name_to_unit(plural, UT_ASCII, unit);
    if (st == UT_SUCCESS && symbol)
        st = ut_map_symbol_to_unit(symbol, UT_ASCII, unit);
    if (st == UT_SUCCESS && symbol2)
        st = ut_map_symbol_to_unit(symbol2, UT_ASCII, unit);
    if (st == UT_SUCCESS && base) {
        st = ut_map_unit_to_symbol(unit, symbol, UT_ASCII);
        if (st == UT_SUCCESS)
            st = ut_map_unit_to_name(unit, name, UT_ASCII);
    }
    return st;
}

/* The small system, or NULL (message in err). */
static ut_system *build_small(ts_err *err)
{
    ut_system *sys = ut_new_system();
    if (!sys) {
        ts_fail(err, TS_ENOMEM, "units: cannot make a unit system");
        return NULL;
    }
    ut_status st = UT_SUCCESS;
    const char *what = "";
    for (size_t i = 0;
         st == UT_SUCCESS && i < sizeof small_base / sizeof small_base[0];
         i++) {
        /* The radian is dimensionless, as in udunits2-derived.xml. */
        int radian = !strcmp(small_base[i][2], "rad");
        ut_unit *u = radian ? ut_new_dimensionless_unit(sys)
                            : ut_new_base_unit(sys);
        what = small_base[i][0];
        st = u ? map_unit(u, small_base[i][0], small_base[i][1],
                          small_base[i][2], NULL, 1)
               : ut_get_status();
        ut_free(u);
    }
    for (size_t i = 0;
         st == UT_SUCCESS && i < sizeof small_prefix / sizeof small_prefix[0];
         i++) {
        what = small_prefix[i].name;
        st = ut_add_name_prefix(sys, small_prefix[i].name,
                                small_prefix[i].value);
        if (st == UT_SUCCESS)
            st = ut_add_symbol_prefix(sys, small_prefix[i].symbol,
                                      small_prefix[i].value);
    }
    for (size_t i = 0;
         st == UT_SUCCESS && i < sizeof small_units / sizeof small_units[0];
         i++) {
        what = small_units[i].definition;
        ut_unit *u = ut_parse(sys, small_units[i].definition, UT_ASCII);
        st = u ? map_unit(u, small_units[i].name, small_units[i].plural,
                          small_units[i].symbol, small_units[i].symbol2, 0)
               : ut_get_status();
        ut_free(u);
    }
    if (st != UT_SUCCESS) {
        ts_fail(err, TS_EUNIT, "units: cannot make the unit '%s' (udunits "
                "status %d)", what, (int)st);
        ut_free_system(sys);
        return NULL;
    }
    if (add_ours(sys, err) != TS_OK) {
        ut_free_system(sys);
        return NULL;
    }
    return sys;
}

/* udunits2's whole database (UDUNITS2_XML_PATH, else its default path)
 * with towstab's additions, or NULL (message in err). */
static ut_system *read_full(ts_err *err)
{
    ut_system *sys = ut_read_xml(NULL);
    if (!sys) {
        ut_status st = ut_get_status();
        const char *env = getenv("UDUNITS2_XML_PATH");
        ts_fail(err, st == UT_OS ? TS_EIO : TS_EUNIT,
                "units: cannot read the udunits2 database (%s%s, udunits "
                "status %d)",
                env ? "UDUNITS2_XML_PATH=" : "default path", env ? env : "",
                (int)st);
        return NULL;
    }
    if (add_ours(sys, err) != TS_OK) {
        ut_free_system(sys);
        return NULL;
    }
    return sys;
}

const char *tsi_units_small_word(size_t i)
{
    size_t nb = sizeof small_base / sizeof small_base[0];
    size_t nu = sizeof small_units / sizeof small_units[0];
    size_t np = sizeof small_prefixed / sizeof small_prefixed[0];
    size_t na = sizeof alias / sizeof alias[0];
    static const char *const slug[] = {"slug", "slugs"};
    if (i < 3 * nb)
        return small_base[i / 3][i % 3];
    i -= 3 * nb;
    if (i < 4 * nu) {
        /* A missing plural or symbol reads as its unit's name. */
        const char *w[] = {small_units[i / 4].name, small_units[i / 4].plural,
                           small_units[i / 4].symbol,
                           small_units[i / 4].symbol2};
        return w[i % 4] ? w[i % 4] : w[0] ? w[0] : w[2];
    }
    i -= 4 * nu;
    if (i < np)
        return small_prefixed[i];
    i -= np;
    if (i < na)
        return alias[i][0];
    i -= na;
    return i < 2 ? slug[i] : NULL;
}

void tsi_units_made(const ts_units *u, int *small, int *full)
{
    *small = u->db->small != NULL;
    *full = u->db->full != NULL;
}

/* 1 when `word` (len characters) is one of the small system's words. */
static int small_word(const char *word, size_t len)
{
    for (size_t i = 0;; i++) {
        const char *w = tsi_units_small_word(i);
        if (!w)
            return 0;
        if (strlen(w) == len && memcmp(w, word, len) == 0)
            return 1;
    }
}

/* 1 when every word of `text` (runs of letters and '_'; NULL is none) is
 * a word of the small system and the rest is digits and the operators of
 * products, quotients and powers. Any other character ('%', a quote, '@',
 * a byte beyond ASCII) is a unit of its own or udunits' syntax for
 * something else: the whole database reads it. */
static int small_covers(const char *text)
{
    if (!text)
        return 1;
    for (const char *p = text; *p;) {
        if (!isalpha((unsigned char)*p) && *p != '_') {
            if (!isdigit((unsigned char)*p) && !strchr(" \t.*/^()-+", *p))
                return 0;
            p++;
            continue;
        }
        const char *w = p;
        while (isalpha((unsigned char)*p) || *p == '_')
            p++;
        if (!small_word(w, (size_t)(p - w)))
            return 0;
    }
    return 1;
}

/* The system in which to read the units `a` and `b` (either may be NULL)
 * into *sys: the small one when it knows every word of both and
 * UDUNITS2_XML_PATH does not name a database, else the whole one; read or
 * built on first use. TS_OK, or the code of the failure (message in err). */
static int system_for(const ts_units *u, const char *a, const char *b,
                      ut_system **sys, ts_err *err)
{
    units_db *db = u->db;
    ts_err own = {0};
    const char *path = getenv("UDUNITS2_XML_PATH");
    if (!(path && path[0]) && small_covers(a) && small_covers(b)) {
        if (!db->small)
            db->small = build_small(&own);
        *sys = db->small;
    } else {
        if (!db->full)
            db->full = read_full(&own);
        *sys = db->full;
    }
    if (*sys)
        return TS_OK;
    return ts_fail(err, own.code, "%s", own.msg);
}

ts_units *ts_units_alloc(ts_err *err)
{
    /* udunits reports problems (and, while reading its XML database,
     * harmless notes about overridden definitions) on stderr through a
     * handler that is process-wide, not per ut_system. The library must not
     * print, so we install ut_ignore for the whole process; every failure
     * is still seen through ut_get_status() and reported in err. */
    ut_set_error_message_handler(ut_ignore);
    ts_units *u = calloc(1, sizeof *u);
    units_db *db = calloc(1, sizeof *db);
    if (!u || !db) {
        free(u);
        free(db);
        ts_fail(err, TS_ENOMEM, "ts_units_alloc: out of memory");
        return NULL;
    }
    u->db = db;
    return u;
}

void ts_units_free(ts_units *u)
{
    if (!u)
        return;
    ut_free_system(u->db->small);
    ut_free_system(u->db->full);
    free(u->db);
    free(u);
}

/* ------------------------------------------------------------------ */
/* Messages                                                             */

/* Copy `text` into buf[size] in double quotes, escaping control and
 * non-ASCII bytes and shortening it to QUOTE_MAX characters. */
static const char *quote(const char *text, char *buf, size_t size)
{
    size_t n = 0;
    if (size < 8)
        return "";
    buf[n++] = '"';
    int shortened = 0;
    size_t count = 0;
    for (const unsigned char *p = (const unsigned char *)text; *p;
         p++, count++) {
        if (n + 8 >= size || count >= QUOTE_MAX) {
            shortened = 1;
            break;
        }
        if (*p == '"' || *p == '\\') {
            buf[n++] = '\\';
            buf[n++] = (char)*p;
        } else if (*p < 0x20 || *p >= 0x7f) {
            n += (size_t)snprintf(buf + n, size - n, "\\x%02x", *p);
        } else {
            buf[n++] = (char)*p;
        }
    }
    if (shortened && n + 4 < size) {
        memcpy(buf + n, "...", 3);
        n += 3;
    }
    buf[n++] = '"';
    buf[n] = '\0';
    return buf;
}

#define QUOTE_BUF (4 * QUOTE_MAX + 16)

/* Dimensions named in words, most common first. The SI unit is shown in
 * parentheses. Entries are matched with units_match() below. */
static const struct {
    const char *si;
    const char *words;
} dimension_names[] = {
    {"m", "a length"},
    {"kg", "a mass"},
    {"N", "a force"},
    {"s", "a time"},
    {"m/s", "a speed"},
    {"m/s^2", "an acceleration"},
    {"N/m", "a force per length"},
    {"kg/m", "a mass per length"},
    {"rad/s", "an angular rate"},
    {"rad", "an angle"},
    {"Hz", "a frequency"},
    {"kg/m^3", "a density"},
    {"N*m^2", "a bending stiffness (force times area)"},
    {"m^2", "an area"},
    {"m^3", "a volume"},
    {"rad/s^2", "an angular acceleration"},
    {"Pa", "a pressure"},
    {"N*m", "an energy or a moment"},
    {"W", "a power"},
    {"kg/s", "a mass flow"},
    {"N*s/m", "a damping (force per speed)"},
    {"K", "a temperature"},
    {"1", "a plain number"},
};

/* 1 when a and b have the same dimension, radians included.
 * ut_are_convertible is not enough: it also accepts reciprocal units ("5 s"
 * would become 0.2 Hz, "2 m" 0.5 m^-1) and ignores radians. Instead the
 * ratio a/b must be dimensionless and its definition must not mention
 * radians (udunits formats an angle ratio as "rad", a pure number as "1"). */
static int units_match(const ut_unit *a, const ut_unit *b)
{
    ut_unit *ratio = ut_divide(a, b);
    if (!ratio)
        return 0;
    int same = ut_are_convertible(ratio,
                                  ut_get_dimensionless_unit_one(
                                      ut_get_system(ratio)));
    if (same) {
        char def[256];
        int n = ut_format(ratio, def, sizeof def, UT_ASCII | UT_DEFINITION);
        same = n >= 0 && (size_t)n < sizeof def && !strstr(def, "rad");
    }
    ut_free(ratio);
    return same;
}

/* "a mass (kg)" or, for an unnamed dimension, "a quantity in m-1.kg.s". */
static const char *describe(const ut_system *sys, const ut_unit *unit,
                            char *buf, size_t size)
{
    for (size_t i = 0; i < sizeof dimension_names / sizeof dimension_names[0];
         i++) {
        ut_unit *ref = ut_parse(sys, dimension_names[i].si, UT_ASCII);
        if (!ref)
            continue;
        int same = units_match(unit, ref);
        ut_free(ref);
        if (same) {
            snprintf(buf, size, "%s (%s)", dimension_names[i].words,
                     dimension_names[i].si);
            return buf;
        }
    }
    char def[256];
    int n = ut_format(unit, def, sizeof def, UT_ASCII | UT_DEFINITION);
    if (n < 0 || (size_t)n >= sizeof def) {
        snprintf(buf, size, "a quantity of another dimension");
        return buf;
    }
    /* Drop the scale factor: "1.488 m-1.kg" -> "m-1.kg". */
    const char *d = def;
    if (isdigit((unsigned char)*d) || *d == '-' || *d == '.') {
        while (*d && *d != ' ')
            d++;
        while (*d == ' ')
            d++;
    }
    /* Unnamed dimensions are short ("m-1.kg.s"); a longer one is cut. */
    int len = snprintf(buf, size, "a quantity in %.100s", *d ? d : "1");
    return len < 0 ? "a quantity of another dimension" : buf;
}

/* ------------------------------------------------------------------ */
/* Scanning                                                             */

/* Length of a decimal number at s: [+-] (d+ [. d*] | . d+) [(e|E) [+-] d+].
 * 0 when s does not start with one. */
static size_t scan_number(const char *s)
{
    size_t i = 0, digits = 0;
    if (s[i] == '+' || s[i] == '-')
        i++;
    while (isdigit((unsigned char)s[i]))
        i++, digits++;
    if (s[i] == '.') {
        i++;
        while (isdigit((unsigned char)s[i]))
            i++, digits++;
    }
    if (digits == 0)
        return 0;
    if (s[i] == 'e' || s[i] == 'E') {
        size_t j = i + 1;
        if (s[j] == '+' || s[j] == '-')
            j++;
        if (isdigit((unsigned char)s[j])) {
            while (isdigit((unsigned char)s[j]))
                j++;
            i = j;
        }
    }
    return i;
}

/* Case-insensitive prefix test. */
static int starts_with_ci(const char *s, const char *prefix)
{
    for (; *prefix; s++, prefix++)
        if (tolower((unsigned char)*s) != *prefix)
            return 0;
    return 1;
}

/* NaN and infinities in the spellings of C and YAML ("nan", ".NaN",
 * "-inf", ".inf", "Infinity"). */
static int is_nonfinite_word(const char *s)
{
    if (*s == '+' || *s == '-')
        s++;
    if (*s == '.')
        s++;
    return starts_with_ci(s, "nan") || starts_with_ci(s, "inf");
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* A number standing alone inside the unit ("ft 3", "2 m") would be read
 * by udunits as a scale factor; it is almost always a typo, so refuse it.
 * Digits are allowed as exponents ("m2", "s-1", "m^3") and in the unit
 * "1/..." at the very start. Returns the offending position or NULL. */
static const char *stray_number(const char *unit)
{
    for (const char *p = unit; *p; p++) {
        if (!isdigit((unsigned char)*p))
            continue;
        if (p == unit) {
            const char *q = p + 1;
            while (*q == ' ')
                q++;
            if (*p == '1' && *q == '/')
                continue;
            return p;
        }
        const char *q = p - 1;
        if (isdigit((unsigned char)*q))
            continue;
        if ((*q == '-' || *q == '+') && q > unit)
            q--;
        if (isalpha((unsigned char)*q) || *q == '^' || *q == '_')
            continue;
        return p;
    }
    return NULL;
}

/* udunits' logarithmic-unit syntax, "lg(re 1 mW)": '(' then blanks then
 * "re". Such a unit is no plain multiple of an SI unit, and udunits 2.2.28
 * leaks a token when a product around one is malformed ("m lg(re m)ft";
 * found by fuzzing, test/fuzz/fuzz_units.c), so it is refused before
 * ut_parse. Returns the position of the '(' or NULL. */
static const char *log_reference(const char *unit)
{
    for (const char *p = strchr(unit, '('); p; p = strchr(p + 1, '(')) {
        const char *q = p + 1;
        while (*q == ' ' || *q == '\t')
            q++;
        if ((q[0] == 'r' || q[0] == 'R') && (q[1] == 'e' || q[1] == 'E'))
            return p;
    }
    return NULL;
}

/* Parentheses that do not pair up: udunits tolerates a trailing ')' ("1
 * ft)" would read as 1 ft), which would let trailing garbage through.
 * Returns 1 when they do not balance. */
static int unbalanced(const char *unit)
{
    int depth = 0;
    for (const char *p = unit; *p; p++) {
        depth += *p == '(';
        depth -= *p == ')';
        if (depth < 0)
            return 1;
    }
    return depth != 0;
}

/* ------------------------------------------------------------------ */
/* Suggestions for the mass-versus-force confusion                      */

/* Rewrite the unit replacing whole identifiers `from[i]` by `to[i]`;
 * returns 1 if anything was replaced (and it fits in out[size]). */
static int rewrite_unit(const char *unit, const char *const from[],
                        const char *const to[], size_t nwords, char *out,
                        size_t size)
{
    size_t n = 0;
    int replaced = 0;
    const char *p = unit;
    while (*p) {
        if (isalpha((unsigned char)*p) || *p == '_') {
            const char *b = p;
            while (isalpha((unsigned char)*p) || *p == '_')
                p++;
            size_t len = (size_t)(p - b);
            const char *word = NULL;
            for (size_t i = 0; i < nwords; i++)
                if (strlen(from[i]) == len && memcmp(from[i], b, len) == 0) {
                    word = to[i];
                    replaced = 1;
                }
            size_t wl = word ? strlen(word) : len;
            if (n + wl + 1 > size)
                return 0;
            memcpy(out + n, word ? word : b, wl);
            n += wl;
        } else {
            if (n + 2 > size)
                return 0;
            out[n++] = *p++;
        }
    }
    out[n] = '\0';
    return replaced;
}

/* When `given` times an acceleration has the dimension of `want`, a mass
 * was given where a force is expected (a weight written "50 lb"); when
 * `given` divided by an acceleration has it, the reverse. Then returns 1
 * and writes into hint[size] a sentence to append, with the rewritten
 * quantity ("50 lbf") when replacing lb/kg by lbf/kgf (or back) works;
 * returns 0 otherwise. */
static int mass_force_hint(const ut_system *sys, const ut_unit *given,
                           const ut_unit *want, const char *number,
                           const char *unit, char *hint, size_t size)
{
    ut_unit *accel = ut_parse(sys, "m/s^2", UT_ASCII);
    if (!accel)
        return 0;
    ut_unit *as_force = ut_multiply(given, accel);
    ut_unit *as_mass = ut_divide(given, accel);
    ut_free(accel);
    int mass_for_force = as_force && units_match(as_force, want);
    int force_for_mass = as_mass && units_match(as_mass, want);
    ut_free(as_force);
    ut_free(as_mass);
    if (!mass_for_force && !force_for_mass)
        return 0;

    static const char *const mass_words[] = {"lb", "lbs", "pound", "pounds",
                                             "kg", "kilogram", "kilograms"};
    static const char *const force_words[] = {"lbf", "lbf", "lbf", "lbf",
                                              "kgf", "kgf", "kgf"};
    static const char *const fmass_words[] = {"lbf", "kgf"};
    static const char *const fforce_words[] = {"lb", "kg"};
    char better[UNIT_TEXT_MAX + 32];
    int ok = mass_for_force
        ? rewrite_unit(unit, mass_words, force_words, 7, better, sizeof better)
        : rewrite_unit(unit, fmass_words, fforce_words, 2, better,
                       sizeof better);
    if (ok) {
        /* Offer the rewrite only if it really has the wanted dimension. */
        ut_unit *b = ut_parse(sys, better, UT_ASCII);
        ok = b && units_match(b, want);
        ut_free(b);
    }
    if (mass_for_force) {
        if (ok)
            snprintf(hint, size, ": for a weight write \"%s %s\", or give it "
                     "as a mass", number, better);
        else
            snprintf(hint, size, ": for a weight use a force unit (N, lbf, "
                     "kgf), or give it as a mass");
    } else {
        if (ok)
            snprintf(hint, size, ": for a mass write \"%s %s\", or give it "
                     "as a weight", number, better);
        else
            snprintf(hint, size, ": for a mass use a mass unit (kg, lb), or "
                     "give it as a weight");
    }
    return 1;
}

/* ------------------------------------------------------------------ */
/* Conversion                                                           */

/* Parse a unit in `sys`, NUL-terminated ASCII. */
static ut_unit *parse_unit(ut_system *sys, const char *text)
{
    return ut_parse(sys, text, UT_ASCII);
}

/* The wrong-dimension message; returns TS_EUNIT. */
static int wrong_dimension(const ut_system *sys, const ut_unit *given,
                           const ut_unit *want, const char *text,
                           const char *number, const char *unit,
                           const char *where, ts_err *err)
{
    char q[QUOTE_BUF], dg[160], dw[160], hint[UNIT_TEXT_MAX + 128];
    describe(sys, given, dg, sizeof dg);
    describe(sys, want, dw, sizeof dw);
    hint[0] = '\0';
    if (!mass_force_hint(sys, given, want, number, unit, hint, sizeof hint)
        && ut_are_convertible(given, want)) {
        /* Same dimension for udunits, but radians differ: an angle or
         * angular rate given as a pure number or a frequency, or the
         * reverse. */
        if (strstr(dw, "angle") || strstr(dw, "angular"))
            snprintf(hint, sizeof hint, ": give an angle unit (rad, deg, "
                     "rad/s, deg/s; 1 Hz is 2 pi rad/s)");
        else
            snprintf(hint, sizeof hint, ": give it without an angle unit "
                     "(1 Hz is 2 pi rad/s)");
    }
    return ts_fail(err, TS_EUNIT, "%s: %s is %s, expected %s%s", where,
                   quote(text, q, sizeof q), dg, dw, hint);
}

int ts_units_parse(const ts_units *u, const char *text, const char *si_unit,
                   const char *where, double *value, ts_err *err)
{
    char q[QUOTE_BUF];
    if (!where)
        where = "value";
    if (!u || !si_unit || !value)
        return ts_fail(err, TS_EINVAL, "%s: ts_units_parse called with a "
                       "NULL %s", where,
                       !u ? "unit system" : !si_unit ? "SI unit" : "result");
    if (!text)
        return ts_fail(err, TS_EINVAL, "%s: no value; expected a number with "
                       "an optional unit", where);

    /* A bare number (most values of most scenes) is SI and needs no unit
     * system: read it here, with the checks below. */
    const char *s = text;
    while (is_space(*s))
        s++;
    size_t nlen = scan_number(s);
    const char *after = s + nlen;
    while (is_space(*after))
        after++;
    if (nlen > 0 && nlen < NUMBER_TEXT_MAX && *after == '\0' &&
        small_covers(si_unit)) {
        char number[NUMBER_TEXT_MAX];
        memcpy(number, s, nlen);
        number[nlen] = '\0';
        char *end = NULL;
        double x = strtod(number, &end);
        if (end == number + nlen && isfinite(x)) {
            *value = x;
            return TS_OK;
        }
    }
    /* Else the system that knows the words after the number (the unit,
     * or the garbage a message quotes) and the SI unit. */
    ut_system *sys;
    int src = system_for(u, si_unit, s + nlen, &sys, err);
    if (src != TS_OK)
        return src;
    ut_unit *want = parse_unit(sys, si_unit);
    if (!want)
        return ts_fail(err, TS_EINVAL, "%s: ts_units_parse called with an "
                       "unknown SI unit '%s'", where, si_unit);
    /* The wanted dimension in words, for messages only (describing costs
     * a few dozen ut_parse calls, so it is not done on success). */
    char dw[160];

    int rc = TS_OK;
    ut_unit *given = NULL;
    cv_converter *conv = NULL;

    if (*s == '\0') {
        rc = ts_fail(err, TS_EINVAL, "%s: empty value; expected %s, e.g. "
                     "\"2.5 %s\"", where,
                     describe(sys, want, dw, sizeof dw), si_unit);
        goto done;
    }
    if (is_nonfinite_word(s)) {
        rc = ts_fail(err, TS_EINVAL, "%s: %s is not a finite number; expected "
                     "%s", where, quote(text, q, sizeof q),
                     describe(sys, want, dw, sizeof dw));
        goto done;
    }
    if (nlen == 0) {
        rc = ts_fail(err, TS_EINVAL, "%s: %s does not start with a number; "
                     "expected %s, e.g. \"2.5 %s\"", where,
                     quote(text, q, sizeof q),
                     describe(sys, want, dw, sizeof dw), si_unit);
        goto done;
    }
    if (nlen >= NUMBER_TEXT_MAX) {
        rc = ts_fail(err, TS_EINVAL, "%s: the number in %s is too long "
                     "(more than %d characters)", where,
                     quote(text, q, sizeof q), NUMBER_TEXT_MAX - 1);
        goto done;
    }
    if ((s[nlen] == 'x' || s[nlen] == 'X') &&
        isxdigit((unsigned char)s[nlen + 1])) {
        rc = ts_fail(err, TS_EINVAL, "%s: %s is not a decimal number; "
                     "expected %s", where, quote(text, q, sizeof q),
                     describe(sys, want, dw, sizeof dw));
        goto done;
    }
    char number[NUMBER_TEXT_MAX];
    memcpy(number, s, nlen);
    number[nlen] = '\0';
    char *end = NULL;
    double x = strtod(number, &end);
    if (end != number + nlen) {
        /* Only a locale with another decimal point gets here. */
        rc = ts_fail(err, TS_EINVAL, "%s: cannot read the number %s (is the "
                     "C locale's decimal point in effect?)", where,
                     quote(number, q, sizeof q));
        goto done;
    }
    if (!isfinite(x)) {
        rc = ts_fail(err, TS_EINVAL, "%s: %s is out of the range of a double",
                     where, quote(text, q, sizeof q));
        goto done;
    }

    /* The unit: the rest, trimmed. */
    const char *ub = s + nlen;
    while (is_space(*ub))
        ub++;
    size_t ulen = strlen(ub);
    while (ulen > 0 && is_space(ub[ulen - 1]))
        ulen--;
    if (ulen == 0) {
        *value = x;     /* no unit: SI */
        goto done;
    }
    if (ulen >= UNIT_TEXT_MAX) {
        rc = ts_fail(err, TS_EUNIT, "%s: the unit in %s is too long (more "
                     "than %d characters)", where, quote(text, q, sizeof q),
                     UNIT_TEXT_MAX - 1);
        goto done;
    }
    char unit[UNIT_TEXT_MAX];
    memcpy(unit, ub, ulen);
    unit[ulen] = '\0';
    for (size_t i = 0; i < ulen; i++)
        if ((unsigned char)unit[i] < 0x20 || (unsigned char)unit[i] >= 0x7f) {
            rc = ts_fail(err, TS_EUNIT, "%s: the unit in %s has a character "
                         "that is not printable ASCII (write m^2, um)", where,
                         quote(text, q, sizeof q));
            goto done;
        }
    const char *stray = stray_number(unit);
    if (stray) {
        char q2[QUOTE_BUF];
        rc = ts_fail(err, TS_EINVAL, "%s: unexpected number %s after the "
                     "value in %s; write one number and one unit, e.g. "
                     "\"2.5 %s\"", where, quote(stray, q2, sizeof q2),
                     quote(text, q, sizeof q), si_unit);
        goto done;
    }
    if (unbalanced(unit)) {
        rc = ts_fail(err, TS_EINVAL, "%s: the parentheses in %s do not "
                     "pair up", where, quote(text, q, sizeof q));
        goto done;
    }
    if (log_reference(unit)) {
        rc = ts_fail(err, TS_EUNIT, "%s: %s uses a logarithmic unit "
                     "(\"lg(re ...)\"); give a plain multiple of %s", where,
                     quote(text, q, sizeof q), si_unit);
        goto done;
    }

    given = parse_unit(sys, unit);
    if (!given) {
        char q2[QUOTE_BUF];
        ut_status st = ut_get_status();
        /* A well-formed expression naming an unknown unit is TS_EUNIT;
         * anything else is trailing garbage (TS_EINVAL). udunits 2.2.28
         * reports syntax errors with status UT_SUCCESS, not UT_SYNTAX, so
         * test for UT_UNKNOWN. */
        if (st != UT_UNKNOWN)
            rc = ts_fail(err, TS_EINVAL, "%s: cannot read %s after the number "
                         "in %s (not a unit expression); expected %s", where,
                         quote(unit, q2, sizeof q2), quote(text, q, sizeof q),
                         describe(sys, want, dw, sizeof dw));
        else
            rc = ts_fail(err, TS_EUNIT, "%s: unknown unit %s in %s; expected "
                         "%s", where, quote(unit, q2, sizeof q2),
                         quote(text, q, sizeof q),
                         describe(sys, want, dw, sizeof dw));
        goto done;
    }
    if (!units_match(given, want)) {
        rc = wrong_dimension(sys, given, want, text, number, unit, where, err);
        goto done;
    }
    conv = ut_get_converter(given, want);
    if (!conv) {
        rc = ts_fail(err, TS_EUNIT, "%s: cannot convert %s to %s", where,
                     quote(text, q, sizeof q), si_unit);
        goto done;
    }
    if (cv_convert_double(conv, 0.0) != 0.0) {
        rc = ts_fail(err, TS_EUNIT, "%s: %s uses a unit with an offset "
                     "(like degC or a time since an epoch); give a plain "
                     "multiple of %s", where, quote(text, q, sizeof q),
                     si_unit);
        goto done;
    }
    double si = cv_convert_double(conv, x);
    if (!isfinite(si)) {
        rc = ts_fail(err, TS_EINVAL, "%s: %s is out of the range of a double "
                     "in %s", where, quote(text, q, sizeof q), si_unit);
        goto done;
    }
    *value = si;

done:
    cv_free(conv);
    ut_free(given);
    ut_free(want);
    return rc;
}

int ts_units_from_si(const ts_units *u, double value_si, const char *si_unit,
                     const char *unit, double *out, ts_err *err)
{
    if (!u || !si_unit || !unit || !out)
        return ts_fail(err, TS_EINVAL, "ts_units_from_si: called with a NULL "
                       "argument");
    char q[QUOTE_BUF];
    /* The screening ts_units_parse applies before udunits sees the text:
     * udunits' scanner echoes bytes it cannot match to stdout, and after
     * some syntax errors ("0ft m", "m lg(re m)ft") leaks a token (found by
     * fuzzing, test/fuzz/fuzz_units.c). */
    size_t ulen = strlen(unit);
    const char *bad = ulen >= UNIT_TEXT_MAX ? "is too long" : NULL;
    for (size_t i = 0; !bad && i < ulen; i++)
        if ((unsigned char)unit[i] < 0x20 || (unsigned char)unit[i] >= 0x7f)
            bad = "has a character that is not printable ASCII";
    if (!bad && strcmp(unit, "1") != 0 && stray_number(unit))
        bad = "has a number that is not an exponent";
    if (!bad && log_reference(unit))
        bad = "is logarithmic (\"lg(re ...)\")";
    if (!bad && unbalanced(unit))
        bad = "has parentheses that do not pair up";
    if (bad)
        return ts_fail(err, TS_EUNIT, "ts_units_from_si: the unit %s %s",
                       quote(unit, q, sizeof q), bad);
    ut_system *sys;
    int src = system_for(u, si_unit, unit, &sys, err);
    if (src != TS_OK)
        return src;
    ut_unit *from = parse_unit(sys, si_unit);
    ut_unit *to = parse_unit(sys, unit);
    cv_converter *conv = NULL;
    int rc = TS_OK;
    if (!from || !to) {
        rc = ts_fail(err, TS_EUNIT, "ts_units_from_si: unknown unit %s",
                     quote(!from ? si_unit : unit, q, sizeof q));
        goto done;
    }
    if (!units_match(from, to)) {
        char df[160], dt[160];
        rc = ts_fail(err, TS_EUNIT, "ts_units_from_si: cannot express %s in "
                     "%s: it is %s, not %s", si_unit, quote(unit, q, sizeof q),
                     describe(sys, from, df, sizeof df),
                     describe(sys, to, dt, sizeof dt));
        goto done;
    }
    conv = ut_get_converter(from, to);
    if (!conv) {
        rc = ts_fail(err, TS_EUNIT, "ts_units_from_si: cannot convert %s to "
                     "%s", si_unit, quote(unit, q, sizeof q));
        goto done;
    }
    *out = cv_convert_double(conv, value_si);

done:
    cv_free(conv);
    ut_free(to);
    ut_free(from);
    return rc;
}

/* ---- display units ------------------------------------------------------ */

/* The quantities: name, another name, SI unit, imperial unit. */
static const struct {
    const char *name, *alias, *si, *imperial;
} quantities[TS_QTY_COUNT] = {
    {"length", NULL, "m", "ft"},
    {"force", NULL, "N", "lbf"},
    {"speed", NULL, "m/s", "knot"},
    {"turn_rate", "angular_rate", "rad/s", "rad/s"},
    {"time", NULL, "s", "s"},
    {"frequency", NULL, "Hz", "Hz"},
    {"angle", NULL, "rad", "deg"},
    {"mass", NULL, "kg", "lb"},
};

/* Exact factors of the imperial units (SI value times factor), so that
 * the presets need no unit database. */
static const struct {
    const char *unit;
    double factor;
} known[] = {
    {"rad/s", 1.0}, {"s", 1.0}, {"Hz", 1.0}, {"deg", 180.0 / M_PI},
    {"ft", 1.0 / 0.3048},                 /* 1 ft = 0.3048 m */
    {"lbf", 1.0 / 4.4482216152605},       /* 1 lbf = 4.4482216152605 N */
    {"knot", 3600.0 / 1852.0},            /* 1 knot = 1852 m / h */
    {"lb", 1.0 / 0.45359237},             /* 1 lb = 0.45359237 kg */
};

const char *ts_quantity_name(ts_quantity q)
{
    return q >= 0 && q < TS_QTY_COUNT ? quantities[q].name : "?";
}

const char *ts_quantity_si(ts_quantity q)
{
    return q >= 0 && q < TS_QTY_COUNT ? quantities[q].si : "?";
}

static void set_known(ts_display *d, ts_quantity q, const char *unit)
{
    snprintf(d->unit[q], sizeof d->unit[q], "%s", unit);
    d->factor[q] = 1.0;
    for (size_t k = 0; k < sizeof known / sizeof known[0]; k++)
        if (!strcmp(known[k].unit, unit))
            d->factor[q] = known[k].factor;
}

/* SI (what ts_display_si copies), read-only. */
static const ts_display display_si = {
    {"m", "N", "m/s", "rad/s", "s", "Hz", "deg", "kg"},
    {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 180.0 / M_PI, 1.0}};

const ts_display *ts_display_or_si(const ts_display *d)
{
    return d ? d : &display_si;
}

void ts_display_si(ts_display *d) { *d = display_si; }

static void display_imperial(ts_display *d)
{
    for (int q = 0; q < TS_QTY_COUNT; q++)
        set_known(d, (ts_quantity)q, quantities[q].imperial);
}

int ts_display_parse(const ts_units *u, const char *spec, const char *where,
                     ts_display *d, ts_err *err)
{
    ts_display_si(d);
    char buf[256];
    if (!spec || strlen(spec) >= sizeof buf)
        return ts_fail(err, TS_EINVAL, "%s: expected si, imperial or "
                       "QUANTITY=UNIT items, got %s", where,
                       spec ? "a text too long" : "nothing");
    snprintf(buf, sizeof buf, "%s", spec);
    ts_display out;
    ts_display_si(&out);
    int n = 0;
    for (char *tok = buf, *next; tok; tok = next) {
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        while (is_space(*tok))
            tok++;
        size_t len = strlen(tok);
        while (len > 0 && is_space(tok[len - 1]))
            tok[--len] = '\0';
        n++;
        if (!strcmp(tok, "si") || !strcmp(tok, "SI")) {
            ts_display_si(&out);
            continue;
        }
        if (!strcmp(tok, "imperial")) {
            display_imperial(&out);
            continue;
        }
        char *eq = strchr(tok, '=');
        if (!eq)
            return ts_fail(err, TS_EINVAL, "%s: '%s': expected si, imperial "
                           "or QUANTITY=UNIT (e.g. speed=knot) with QUANTITY "
                           "one of length, force, speed, turn_rate, time, "
                           "frequency, angle, mass", where, tok);
        *eq = '\0';
        char *name = tok, *unit = eq + 1;
        size_t nl = strlen(name);
        while (nl > 0 && is_space(name[nl - 1]))
            name[--nl] = '\0';
        while (is_space(*unit))
            unit++;
        int q = -1;
        for (int k = 0; k < TS_QTY_COUNT && q < 0; k++)
            if (!strcmp(name, quantities[k].name) ||
                (quantities[k].alias && !strcmp(name, quantities[k].alias)))
                q = k;
        if (q < 0)
            return ts_fail(err, TS_EINVAL, "%s: unknown quantity '%s'; "
                           "expected length, force, speed, turn_rate, time, "
                           "frequency, angle or mass", where, name);
        if (!unit[0] || strlen(unit) >= TS_DISPLAY_UNIT_MAX)
            return ts_fail(err, TS_EINVAL, "%s: %s: expected a unit of "
                           "%s, got '%s'", where, name, quantities[q].si,
                           unit);
        double one, zero;
        ts_err e = {0};
        if (ts_units_from_si(u, 1.0, quantities[q].si, unit, &one, &e) ||
            ts_units_from_si(u, 0.0, quantities[q].si, unit, &zero, &e))
            return ts_fail(err, TS_EUNIT, "%s: %s=%s: not a unit of %s (%s)",
                           where, name, unit, quantities[q].si, e.msg);
        if (zero != 0 || !(one > 0) || !isfinite(one))
            return ts_fail(err, TS_EUNIT, "%s: %s=%s: not a positive "
                           "multiple of %s", where, name, unit,
                           quantities[q].si);
        snprintf(out.unit[q], sizeof out.unit[q], "%s", unit);
        out.factor[q] = one;
    }
    if (n == 0)
        return ts_fail(err, TS_EINVAL, "%s: expected si, imperial or "
                       "QUANTITY=UNIT items, got '%s'", where, spec);
    *d = out;
    return TS_OK;
}

double ts_display_value(const ts_display *d, ts_quantity q, double si)
{
    return q >= 0 && q < TS_QTY_COUNT ? si * d->factor[q] : si;
}

const char *ts_display_unit(const ts_display *d, ts_quantity q)
{
    return q >= 0 && q < TS_QTY_COUNT ? d->unit[q] : "";
}

/* The quantity whose SI unit is `si` (deg: the angle), or -1. */
static int si_quantity(const char *si, size_t len)
{
    if (len == 3 && !strncmp(si, "deg", 3))
        return TS_QTY_ANGLE;
    for (int q = 0; q < TS_QTY_COUNT; q++)
        if (strlen(quantities[q].si) == len &&
            !strncmp(quantities[q].si, si, len))
            return q;
    return -1;
}

double ts_display_convert(const ts_display *d, const char *si_unit, double v,
                          char *unit, size_t size)
{
    size_t len = strlen(si_unit);
    int q = si_quantity(si_unit, len);
    if (q >= 0) {
        /* A value already in degrees is turned back into radians. */
        double si = !strcmp(si_unit, "deg") ? v * (M_PI / 180.0) : v;
        snprintf(unit, size, "%s", d->unit[q]);
        return si * d->factor[q];
    }
    const char *slash = strchr(si_unit, '/');
    if (slash) {
        int a = si_quantity(si_unit, (size_t)(slash - si_unit));
        int b = si_quantity(slash + 1, strlen(slash + 1));
        int one = slash - si_unit == 1 && si_unit[0] == '1';
        if (b >= 0 && a != b && (a >= 0 || one)) {
            snprintf(unit, size, "%s/%s", a >= 0 ? d->unit[a] : "1",
                     d->unit[b]);
            return v * (a >= 0 ? d->factor[a] : 1.0) / d->factor[b];
        }
    }
    snprintf(unit, size, "%s", si_unit);
    return v;
}

void ts_display_unit_token(const char *unit, char *buf, size_t size)
{
    size_t n = 0;
    for (const char *p = unit; *p && n + 1 < size; p++) {
        if (*p == '/') {
            const char *per = "_per_";
            for (; *per && n + 1 < size; per++)
                buf[n++] = *per;
        } else if (*p != '^' && !is_space(*p)) {
            buf[n++] = *p == '*' || *p == '.' ? '_' : *p;
        }
    }
    if (size > 0)
        buf[n] = '\0';
}
