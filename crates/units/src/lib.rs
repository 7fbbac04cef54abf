//! plantwide-units
