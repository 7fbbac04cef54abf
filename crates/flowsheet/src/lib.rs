//! plantwide-flowsheet
