#pragma once
// Internal to common/: what VTK reports, caught instead of printed. VTK prints its errors as a
// block of coloured, time-stamped lines on stderr (its logger and its output window); the course
// turns them into one line inside the fem::Error it throws.

#include <string>
#include <vector>

class vtkAlgorithm;

namespace fem::io::detail {

/// Replaces VTK's output (its logger on stderr and its output window) by one that keeps each
/// message for the innermost VtkErrors alive, or, when none is, prints it as one line
/// "VTK: <reason>" on stderr. Called by VtkErrors and by the renderer; later calls do nothing.
void route_vtk_output();

/// Collects what VTK reports while it exists: the errors and warnings of one algorithm (and of its
/// pipeline), and every other message VTK would have printed meanwhile (e.g. its XML parser's).
class VtkErrors {
public:
    /// Collects the messages of algorithm (may be null: then only the others).
    explicit VtkErrors(vtkAlgorithm* algorithm);
    ~VtkErrors();
    VtkErrors(const VtkErrors&) = delete;
    VtkErrors& operator=(const VtkErrors&) = delete;

    bool any() const { return !messages_.empty() || !pipeline_.empty(); }

    /// One line: each message's first line without VTK's "ERROR: In file, line N" and
    /// "vtkClass (0x…): " prefixes, joined by "; ". The pipeline's ("returned failure for request")
    /// only when there is nothing else.
    std::string text() const;

    /// Records a message VTK reported (called by the observers and the output window).
    void add(const char* message, bool from_pipeline);

private:
    std::vector<std::string> messages_, pipeline_;
    VtkErrors* outer_;            // the collector that was active before this one
    vtkAlgorithm* algorithm_;     // observed, if any
    unsigned long own_error_ = 0, own_warning_ = 0, pipeline_error_ = 0;  // observer tags
};

}  // namespace fem::io::detail
