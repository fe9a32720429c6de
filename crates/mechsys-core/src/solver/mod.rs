//! Complementarity problems of contact mechanics (section 2.5): linear complementarity problems
//! and friction-contact problems, with the solvers that time-stepping and event-driven schemes share.
