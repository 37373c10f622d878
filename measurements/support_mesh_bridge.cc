// Support meshes: the only file in phytocal that touches assimp (reading
// OBJ/PLY) and CGAL (AABB tree closest-point queries).  See
// measurements/support_mesh.h.  Every extern "C" function catches every
// exception; none crosses into C.

#include "measurements/support_mesh_module_internal.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iterator>
#include <memory>
#include <new>
#include <vector>

namespace {

// Simple_cartesian<double>: plain double arithmetic.  A closest point on a
// triangle is a projection, computed exactly up to rounding; no predicate
// needs exactness here.
typedef CGAL::Simple_cartesian<double> Kernel;
typedef Kernel::Point_3 Point;
typedef Kernel::Triangle_3 Triangle;
typedef std::vector<Triangle>::const_iterator TriangleIterator;
typedef CGAL::AABB_triangle_primitive<Kernel, TriangleIterator> Primitive;
typedef CGAL::AABB_traits<Kernel, Primitive> Traits;
typedef CGAL::AABB_tree<Traits> Tree;

}  // namespace

struct phc_support_mesh {
    std::vector<double> vertices;     // 3 nv
    std::vector<size_t> triangles;    // 3 nt
    std::vector<Triangle> cgal;       // nt, same order
    std::vector<double> normals;      // 3 nt, unit or zero
    double lo[3], hi[3];
    std::unique_ptr<Tree> tree;
    // The certified answers (certify below): this mesh's number
    // (unique in the process, never 0), the cells' edge (m) and its inverse, how far
    // beyond a query's distance the second-closest triangle is looked for (m).
    std::uint64_t serial;
    double cell, per_cell, reach;
    std::atomic<int> certified{1};            // phc_support_mesh_certificates
    mutable std::atomic<size_t> tree_queries{0}; // phc_support_mesh_tree_queries (counted by const queries)
};

namespace {

// Builds triangles, normals, bounds and the tree from vertices/triangles.
void build(phc_support_mesh *m)
{
    const size_t nt = m->triangles.size() / 3;
    m->cgal.reserve(nt);
    m->normals.assign(3 * nt, 0.0);
    for (int k = 0; k < 3; ++k) {
        m->lo[k] = HUGE_VAL;
        m->hi[k] = -HUGE_VAL;
    }
    for (size_t i = 0; i < m->vertices.size() / 3; ++i)
        for (int k = 0; k < 3; ++k) {
            m->lo[k] = std::fmin(m->lo[k], m->vertices[3 * i + k]);
            m->hi[k] = std::fmax(m->hi[k], m->vertices[3 * i + k]);
        }
    for (size_t t = 0; t < nt; ++t) {
        const double *a = &m->vertices[3 * m->triangles[3 * t]];
        const double *b = &m->vertices[3 * m->triangles[3 * t + 1]];
        const double *c = &m->vertices[3 * m->triangles[3 * t + 2]];
        m->cgal.emplace_back(Point(a[0], a[1], a[2]), Point(b[0], b[1], b[2]),
                             Point(c[0], c[1], c[2]));
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 0)
            for (int k = 0; k < 3; ++k)
                m->normals[3 * t + k] = n[k] / len;
    }
    m->tree.reset(new Tree(m->cgal.begin(), m->cgal.end()));
    // Builds the search structure now, so that later queries only read.
    m->tree->accelerate_distance_queries();
    static std::atomic<std::uint64_t> serials(0);
    m->serial = ++serials;
    const double diag = std::sqrt((m->hi[0] - m->lo[0]) * (m->hi[0] - m->lo[0]) +
                                  (m->hi[1] - m->lo[1]) * (m->hi[1] - m->lo[1]) +
                                  (m->hi[2] - m->lo[2]) * (m->hi[2] - m->lo[2]));
    m->cell = diag > 0 ? diag / 256 : 1;
    m->per_cell = 1 / m->cell;
    m->reach = diag > 0 ? diag / 32 : 1;
}

// The triangles whose bounding boxes overlap a box (an AABB tree
// traversal that tests boxes only: every triangle that comes within the
// box is listed, maybe some more).
class Box_gather {
  public:
    explicit Box_gather(std::vector<size_t> *out, TriangleIterator first) : out_(out), first_(first) {}
    bool go_further() const { return true; }
    void intersection(const CGAL::Bbox_3 &q, const Primitive &p)
    {
        if (CGAL::do_overlap(q, p.datum().bbox()))
            out_->push_back(static_cast<size_t>(p.id() - first_));
    }
    template <class Node> bool do_intersect(const CGAL::Bbox_3 &q, const Node &node) const
    {
        return CGAL::do_overlap(q, node.bbox());
    }

  private:
    std::vector<size_t> *out_;
    TriangleIterator first_;
};

// Certified closest triangles (ours; exact).  A query at x₀ whose closest
// triangle T lies at distance d₀ while every other triangle lies at d₂ or
// farther certifies T for every x with |x − x₀| < ρ = (d₂ − d₀)/2 − margin:
// the distance to the mesh is 1-Lipschitz, so T lies within d₀ + |x − x₀|
// of x and every other triangle beyond d₂ − |x − x₀|, farther by more than
// the margin.  The tree's own traversal then ends on T as well (a triangle
// replaces its best only when not farther), so the projection of x on T is
// its answer bit for bit (the same CGAL projection of the same two
// arguments).  The margin, 1e-9·(1 + |x₀|∞) m, covers the rounding of the
// projections and distances (a few ulps of the coordinates).  Certificates
// are kept per thread in a table indexed by the query's cell (edge
// m->cell): a later query in the same cell within ρ of x₀ costs one
// projection instead of a tree traversal.
struct Certificate {
    std::uint64_t serial;  // the mesh's; 0: empty
    double x0[3], rho;
    size_t triangle;
};
enum { CERTIFICATES = 1 << 14 };
thread_local std::unique_ptr<Certificate[]> certificates;

size_t certificate_slot(const phc_support_mesh *m, const double x[3])
{
    std::uint64_t h = m->serial * 0x9E3779B97F4A7C15ull;
    for (int k = 0; k < 3; ++k) {
        const double u = x[k] * m->per_cell; /* (truncated: the cells at 0 are two wide, no matter) */
        const std::int64_t iu = std::fabs(u) < 9e15 ? static_cast<std::int64_t>(u) : 0;
        h = (h ^ static_cast<std::uint64_t>(iu)) * 0x100000001B3ull;
    }
    h ^= h >> 33; /* MurmurHash3's finaliser: every bit of the cell moves the slot */
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ull;
    h ^= h >> 33;
    return static_cast<size_t>(h) & (CERTIFICATES - 1);
}

// The distance from x to the closest point of triangle t (m).
double distance_to(const phc_support_mesh *m, size_t t, const Point &x)
{
    const Point c = Kernel().construct_projected_point_3_object()(m->cgal[t], x);
    return std::sqrt(CGAL::squared_distance(x, c));
}

// After the tree's answer (triangle t, point c) for x: the certificate of
// t around x, stored in x's slot (nothing when ρ <= 0).
void certify(const phc_support_mesh *m, const double x[3], const Point &q, const Point &c, size_t t)
{
    if (!certificates)
        certificates.reset(new Certificate[CERTIFICATES]());
    Certificate &e = certificates[certificate_slot(m, x)];
    e.serial = 0;
    const double d0 = std::sqrt(CGAL::squared_distance(q, c));
    const double reach = d0 + m->reach;
    const double margin = 1e-9 * (1 + std::fmax(std::fabs(x[0]), std::fmax(std::fabs(x[1]), std::fabs(x[2]))));
    // every triangle not listed lies farther than `reach` (box of half edge
    // reach·(1 + 1e-12) around x, compared exactly)
    const double half = reach * (1 + 1e-12);
    const CGAL::Bbox_3 box(x[0] - half, x[1] - half, x[2] - half, x[0] + half, x[1] + half, x[2] + half);
    thread_local std::vector<size_t> near;
    near.clear();
    Box_gather gather(&near, m->cgal.begin());
    m->tree->traversal(box, gather);
    double d2 = reach;
    for (size_t k : near)
        if (k != t)
            d2 = std::fmin(d2, distance_to(m, k, q));
    const double rho = 0.5 * (d2 - d0) - margin;
    if (!(rho > 0))
        return;
    for (int k = 0; k < 3; ++k)
        e.x0[k] = x[k];
    e.rho = rho;
    e.triangle = t;
    e.serial = m->serial;
}

// The parameter s in [0, 1] of the point of segment p0 p1 closest to
// segment q0 q1 (Ericson, "Real-Time Collision Detection", 2005, §5.1.9,
// ClosestPtSegmentSegment; parallel segments: s = 0), and in *dist2 the
// squared distance between the two closest points (m²).  Coordinates in m.
double segment_segment_s(const double p0[3], const double p1[3], const double q0[3], const double q1[3],
                         double *dist2)
{
    double d1[3], d2[3], r[3];
    for (int k = 0; k < 3; ++k) {
        d1[k] = p1[k] - p0[k];
        d2[k] = q1[k] - q0[k];
        r[k] = p0[k] - q0[k];
    }
    const double a = d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2];
    const double e = d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2];
    const double f = d2[0] * r[0] + d2[1] * r[1] + d2[2] * r[2];
    const double c = d1[0] * r[0] + d1[1] * r[1] + d1[2] * r[2];
    const double b = d1[0] * d2[0] + d1[1] * d2[1] + d1[2] * d2[2];
    auto clamp01 = [](double v) { return std::fmin(1.0, std::fmax(0.0, v)); };
    double s = 0, u = 0;
    if (!(a > 0))
        u = e > 0 ? clamp01(f / e) : 0;
    else if (!(e > 0))
        s = clamp01(-c / a);
    else {
        const double denom = a * e - b * b;
        s = denom > 0 ? clamp01((b * f - c * e) / denom) : 0;
        u = (b * s + f) / e;
        if (u < 0) {
            u = 0;
            s = clamp01(-c / a);
        } else if (u > 1) {
            u = 1;
            s = clamp01((b - c) / a);
        }
    }
    *dist2 = 0;
    for (int k = 0; k < 3; ++k) {
        const double g = p0[k] + s * d1[k] - q0[k] - u * d2[k];
        *dist2 += g * g;
    }
    return s;
}

}  // namespace

extern "C" {

phc_support_mesh *phc_support_mesh_read(const char *path, phc_error *err)
{
    if (!path) {
        phc_error_set(err, PHC_ERR_INVALID, "support mesh: no file name");
        return nullptr;
    }
    std::FILE *f = std::fopen(path, "rb");
    if (!f) {
        phc_error_set(err, PHC_ERR_IO, "%s: cannot open: %s", path, std::strerror(errno));
        return nullptr;
    }
    // assimp 5's PLY reader loops forever on a header without end_header
    // (found by phytocal grow's bad-input tests): refuse such a file first.
    char head[65536];
    const size_t got = std::fread(head, 1, sizeof head - 1, f);
    std::fclose(f);
    head[got] = '\0';
    if (got >= 3 && std::strncmp(head, "ply", 3) == 0 && !std::strstr(head, "\nend_header")) {
        phc_error_set(err, PHC_ERR_INPUT,
                      "%s: a PLY file whose header has no end_header line (within its first 64 KiB)", path);
        return nullptr;
    }
    phc_support_mesh *m = nullptr;
    try {
        Assimp::Importer importer;
        const aiScene *scene = importer.ReadFile(
            path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
        if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE && scene->mNumMeshes == 0)) {
            const char *why = importer.GetErrorString();
            if (!why || !*why)
                why = "no reason given";
            // assimp refuses a file whose meshes hold no faces (an OBJ of
            // vertices only) as "No output meshes": say what that means.
            if (std::strstr(why, "No output meshes") || std::strstr(why, "no meshes"))
                phc_error_set(err, PHC_ERR_INPUT,
                              "%s: no triangles (assimp: %s); a support must be a surface", path,
                              why);
            else
                phc_error_set(err, PHC_ERR_INPUT, "%s: assimp cannot read it as a mesh: %s", path,
                              why);
            return nullptr;
        }
        m = new phc_support_mesh();
        for (unsigned im = 0; im < scene->mNumMeshes; ++im) {
            const aiMesh *mesh = scene->mMeshes[im];
            const size_t base = m->vertices.size() / 3;
            for (unsigned iv = 0; iv < mesh->mNumVertices; ++iv) {
                const aiVector3D &p = mesh->mVertices[iv];
                const double xyz[3] = {p.x, p.y, p.z};
                for (int k = 0; k < 3; ++k) {
                    if (!std::isfinite(xyz[k])) {
                        phc_error_set(err, PHC_ERR_INPUT,
                                      "%s: mesh %u vertex %u: coordinate %c is not finite", path,
                                      im, iv, "xyz"[k]);
                        delete m;
                        return nullptr;
                    }
                    m->vertices.push_back(xyz[k]);
                }
            }
            for (unsigned it = 0; it < mesh->mNumFaces; ++it) {
                const aiFace &face = mesh->mFaces[it];
                if (face.mNumIndices != 3)
                    continue;  // points and lines: not a surface
                for (int k = 0; k < 3; ++k)
                    m->triangles.push_back(base + face.mIndices[k]);
            }
        }
        if (m->triangles.empty()) {
            phc_error_set(err, PHC_ERR_INPUT,
                          "%s: no triangles (%zu vertices in %u meshes; a support must be a "
                          "surface: faces with 3 or more vertices)",
                          path, m->vertices.size() / 3, scene->mNumMeshes);
            delete m;
            return nullptr;
        }
        build(m);
        return m;
    } catch (const std::bad_alloc &) {
        delete m;
        phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory reading the mesh", path);
    } catch (const std::exception &e) {
        delete m;
        phc_error_set(err, PHC_ERR_INPUT, "%s: cannot read the mesh: %s", path, e.what());
    }
    return nullptr;
}

phc_support_mesh *phc_support_mesh_from_arrays(const double *vertices, size_t nv,
                                               const size_t *triangles, size_t nt,
                                               const char *where, phc_error *err)
{
    if (!where)
        where = "support mesh";
    if (nt == 0 || !triangles || !vertices || nv == 0) {
        phc_error_set(err, PHC_ERR_INPUT, "%s: no triangles", where);
        return nullptr;
    }
    for (size_t i = 0; i < 3 * nv; ++i)
        if (!std::isfinite(vertices[i])) {
            phc_error_set(err, PHC_ERR_INPUT, "%s: vertex %zu: coordinate %c is not finite", where,
                          i / 3, "xyz"[i % 3]);
            return nullptr;
        }
    for (size_t i = 0; i < 3 * nt; ++i)
        if (triangles[i] >= nv) {
            phc_error_set(err, PHC_ERR_INPUT,
                          "%s: triangle %zu: vertex index %zu out of range (%zu vertices)", where,
                          i / 3, triangles[i], nv);
            return nullptr;
        }
    phc_support_mesh *m = nullptr;
    try {
        m = new phc_support_mesh();
        m->vertices.assign(vertices, vertices + 3 * nv);
        m->triangles.assign(triangles, triangles + 3 * nt);
        build(m);
        return m;
    } catch (const std::exception &) {
        delete m;
        phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory for %zu triangles", where, nt);
    }
    return nullptr;
}

void phc_support_mesh_free(phc_support_mesh *m) { delete m; }

size_t phc_support_mesh_triangle_count(const phc_support_mesh *m)
{
    return m ? m->triangles.size() / 3 : 0;
}

size_t phc_support_mesh_vertex_count(const phc_support_mesh *m)
{
    return m ? m->vertices.size() / 3 : 0;
}

void phc_support_mesh_bounds(const phc_support_mesh *m, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; ++k) {
        lo[k] = m->lo[k];
        hi[k] = m->hi[k];
    }
}

void phc_support_mesh_vertex(const phc_support_mesh *m, size_t i, double v[3])
{
    for (int k = 0; k < 3; ++k)
        v[k] = m->vertices[3 * i + k];
}

void phc_support_mesh_triangle(const phc_support_mesh *m, size_t t, size_t idx[3])
{
    for (int k = 0; k < 3; ++k)
        idx[k] = m->triangles[3 * t + k];
}

int phc_support_mesh_closest(void *mesh, const double x[3], double c[3], double n[3])
{
    const phc_support_mesh *m = static_cast<const phc_support_mesh *>(mesh);
    if (!m || !std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
        return -1;
    try {
        const Point q(x[0], x[1], x[2]);
        const int certified = m->certified.load(std::memory_order_relaxed);
        if (certified && certificates) {
            const Certificate &e = certificates[certificate_slot(m, x)];
            const double g[3] = {x[0] - e.x0[0], x[1] - e.x0[1], x[2] - e.x0[2]};
            if (e.serial == m->serial && g[0] * g[0] + g[1] * g[1] + g[2] * g[2] < e.rho * e.rho) {
                const Point p = Kernel().construct_projected_point_3_object()(m->cgal[e.triangle], q);
                c[0] = p.x();
                c[1] = p.y();
                c[2] = p.z();
                for (int k = 0; k < 3; ++k)
                    n[k] = m->normals[3 * e.triangle + k];
                return 0;
            }
        }
        const Tree::Point_and_primitive_id pp = m->tree->closest_point_and_primitive(q);
        const size_t t = static_cast<size_t>(pp.second - m->cgal.begin());
        m->tree_queries.fetch_add(1, std::memory_order_relaxed);
        if (certified)
            certify(m, x, q, pp.first, t);
        c[0] = pp.first.x();
        c[1] = pp.first.y();
        c[2] = pp.first.z();
        for (int k = 0; k < 3; ++k)
            n[k] = m->normals[3 * t + k];
        return 0;
    } catch (const std::exception &) {
        return -1;
    }
}

int phc_support_mesh_segment_deepest(void *mesh, const double a[3], const double b[3], double reach, double *t,
                                     double *depth)
{
    const phc_support_mesh *m = static_cast<const phc_support_mesh *>(mesh);
    for (int k = 0; k < 3; ++k)
        if (!std::isfinite(a[k]) || !std::isfinite(b[k]))
            return -1;
    if (!m || !(reach >= 0))
        return -1;
    try {
        CGAL::Bbox_3 box(std::fmin(a[0], b[0]) - reach, std::fmin(a[1], b[1]) - reach,
                         std::fmin(a[2], b[2]) - reach, std::fmax(a[0], b[0]) + reach,
                         std::fmax(a[1], b[1]) + reach, std::fmax(a[2], b[2]) + reach);
        std::vector<Tree::Primitive_id> near;
        m->tree->all_intersected_primitives(box, std::back_inserter(near));
        if (near.empty())
            return 0;
        double best = INFINITY, best_s = 0;
        auto consider = [&](double s) {
            double y[3], c[3], n[3];
            for (int k = 0; k < 3; ++k)
                y[k] = a[k] + s * (b[k] - a[k]);
            if (phc_support_mesh_closest(mesh, y, c, n))
                return;
            const double e[3] = {y[0] - c[0], y[1] - c[1], y[2] - c[2]};
            const double dist = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            const double d = e[0] * n[0] + e[1] * n[1] + e[2] * n[2] >= 0 ? dist : -dist;
            if (d < best) {
                best = d;
                best_s = s;
            }
        };
        consider(0);
        consider(1);
        // A segment that meets no triangle has its points' δ = their
        // distance to the mesh on one side, so its smallest is at an end or
        // at its point closest to an edge: an edge reach or farther from the
        // segment cannot give one below reach (skipped).  A segment that
        // meets a triangle: every edge near it.
        const int cuts = m->tree->do_intersect(Kernel::Segment_3(Point(a[0], a[1], a[2]), Point(b[0], b[1], b[2])));
        for (const Tree::Primitive_id &id : near) {
            const size_t tri = static_cast<size_t>(id - m->cgal.begin());
            for (int k = 0; k < 3; ++k) {
                const double *p = &m->vertices[3 * m->triangles[3 * tri + k]];
                const double *q = &m->vertices[3 * m->triangles[3 * tri + (k + 1) % 3]];
                double dist2;
                const double s = segment_segment_s(a, b, p, q, &dist2);
                if (cuts || dist2 < reach * reach)
                    consider(s);
            }
        }
        if (depth)
            *depth = best;
        if (t)
            *t = best_s;
        return best < reach;
    } catch (const std::exception &) {
        return -1;
    }
}

void phc_support_mesh_certificates(phc_support_mesh *m, int on)
{
    if (m)
        m->certified.store(on != 0, std::memory_order_relaxed);
}

size_t phc_support_mesh_tree_queries(const phc_support_mesh *m)
{
    return m ? m->tree_queries.load(std::memory_order_relaxed) : 0;
}

}  // extern "C"

/* The module's entry point (measurements/support_mesh_module_internal.h):
 * this file is compiled into phytocal_mesh.so, which libphytocal opens on
 * the first support_mesh.h call. */
static const phc_mesh_module_table phc_mesh_module = {
    phc_support_mesh_read,           phc_support_mesh_from_arrays, phc_support_mesh_free,
    phc_support_mesh_triangle_count, phc_support_mesh_vertex_count, phc_support_mesh_bounds,
    phc_support_mesh_vertex,         phc_support_mesh_triangle,    phc_support_mesh_closest,
    phc_support_mesh_certificates,   phc_support_mesh_tree_queries, phc_support_mesh_segment_deepest};

extern "C" const void *phc_mesh_module_entry(int abi)
{
    return abi == PHC_MESH_MODULE_ABI ? &phc_mesh_module : nullptr;
}
