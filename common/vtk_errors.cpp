#include "common/vtk_errors.hpp"

#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>

#include <iostream>
#include <mutex>

namespace fem::io::detail {
namespace {

thread_local VtkErrors* active = nullptr;  // the innermost collector of this thread

/// "ERROR: In file.cxx, line N\nvtkClass (0x...): what\nmore" -> "what".
std::string reason(const char* message)
{
    std::string text = message ? message : "unknown error";
    if (text.starts_with("ERROR: In ") || text.starts_with("Warning: In "))
        text = text.substr(text.find('\n') + 1);
    if (const auto at = text.find("): "); at != std::string::npos && at < text.find('\n'))
        text = text.substr(at + 3);
    text = text.substr(0, text.find('\n'));
    while (!text.empty() && (text.back() == ' ' || text.back() == '\r'))
        text.pop_back();
    return text.empty() ? "unknown error" : text;
}

/// VTK's output window, replaced: a message goes to the active collector, or to stderr in one line.
class CollectingOutputWindow : public vtkOutputWindow {
public:
    static CollectingOutputWindow* New();
    vtkTypeMacro(CollectingOutputWindow, vtkOutputWindow)

    void DisplayText(const char* text) override
    {
        if (active)
            active->add(text, false);
        else
            std::cerr << "VTK: " << reason(text) << '\n';
    }
    void DisplayErrorText(const char* text) override { DisplayText(text); }
    void DisplayWarningText(const char* text) override { DisplayText(text); }
    void DisplayGenericWarningText(const char* text) override { DisplayText(text); }
    void DisplayDebugText(const char*) override {}
};
vtkStandardNewMacro(CollectingOutputWindow);

void record(vtkObject*, unsigned long, void* client, void* call)
{
    static_cast<VtkErrors*>(client)->add(static_cast<const char*>(call), false);
}

void record_pipeline(vtkObject*, unsigned long, void* client, void* call)
{
    static_cast<VtkErrors*>(client)->add(static_cast<const char*>(call), true);
}

}  // namespace

void route_vtk_output()
{
    static std::once_flag once;
    std::call_once(once, [] {
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
        vtkNew<CollectingOutputWindow> window;
        vtkOutputWindow::SetInstance(window);
    });
}

VtkErrors::VtkErrors(vtkAlgorithm* algorithm) : outer_(active), algorithm_(algorithm)
{
    route_vtk_output();
    active = this;
    if (!algorithm_)
        return;
    vtkNew<vtkCallbackCommand> own, pipeline;
    own->SetCallback(&record);
    own->SetClientData(this);
    pipeline->SetCallback(&record_pipeline);
    pipeline->SetClientData(this);
    own_error_ = algorithm_->AddObserver(vtkCommand::ErrorEvent, own);
    own_warning_ = algorithm_->AddObserver(vtkCommand::WarningEvent, own);
    pipeline_error_ = algorithm_->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, pipeline);
}

VtkErrors::~VtkErrors()
{
    active = outer_;
    if (!algorithm_)
        return;
    algorithm_->RemoveObserver(own_error_);
    algorithm_->RemoveObserver(own_warning_);
    algorithm_->GetExecutive()->RemoveObserver(pipeline_error_);
}

void VtkErrors::add(const char* message, bool from_pipeline)
{
    (from_pipeline ? pipeline_ : messages_).push_back(reason(message));
}

std::string VtkErrors::text() const
{
    std::string text;
    for (const std::string& message : messages_.empty() ? pipeline_ : messages_)
        text += (text.empty() ? "" : "; ") + message;
    return text;
}

}  // namespace fem::io::detail
