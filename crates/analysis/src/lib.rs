//! plantwide-analysis
