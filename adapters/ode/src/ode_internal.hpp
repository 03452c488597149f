// Private to mlcp::ode: ODE 0.16.2's internal headers, from Debian's source package (only
// <source>/ode/src is on the include path; the public <ode/...> headers are the installed,
// double-precision ones).
#pragma once

#include <ode/ode.h>

#include "joints/contact.h"
#include "joints/joint.h"
#include "lcp.h"
#include "objects.h"
#include "quickstep.h"
#include "step.h"
#include "util.h"

static_assert(sizeof(dReal) == 8, "mlcp::ode needs ODE built in double precision (dDOUBLE)");
static_assert(dDA__MAX == 6 && dDA_LX == 0 && dDA_AX == 3,
              "ODE Jacobian rows are expected as [linear; angular], 6 wide");
