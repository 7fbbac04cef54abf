//! plantwide-solve
