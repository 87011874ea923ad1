/* common/codes.cl: the numbers the kernels and the host share, defined once.  pyjulia4d/pipeline/codes.py
 * reads this file's #define lines (name, integer value), so Python never restates them. */

/* Pixel status codes written by the march kernel. */
#define STATUS_MISS 0
#define STATUS_HIT 1
#define STATUS_CAPPED 2   /* the step cap ended the march before a hit or the far plane */

/* Guard flags (nothing clamped without being counted).  The march kernel writes them into
 * its flags buffer and the normals kernels OR theirs into the same buffer; the host counts
 * the pixels each fired on (RenderResult.guards). */
#define GUARD_NORMAL_FALLBACK 1   /* degenerate or non-finite normal replaced by the view axis */
#define GUARD_JACOBIAN_TINY 2     /* Jacobian iteration stopped: q_n about to underflow (c ~ 0) */
#define GUARD_ULP_STEP 4          /* de: a step below the spacing of t was raised to one ulp */
#define GUARD_SHELL_MISS 8        /* de: came within epsilon by the estimate, never inside: a miss */

/* march.cl (-D CLIP): a hit on a cut face, the plane's index in bits 5-6 (march/clip.cl). */
#define FLAG_CUT_FACE 16
