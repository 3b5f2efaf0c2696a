// Figures: the on-screen window (MeshWindow) that shows a mesh frame by frame, drawn by the same
// renderers as the PNGs of figures_mesh.cpp, and reports the keys pressed (the scenes' --view).
#include "common/figures.hpp"

#include "common/error.hpp"
#include "common/figures_internal.hpp"

#include <vtkCallbackCommand.h>
#include <vtkNew.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRendererCollection.h>

#include <algorithm>
#include <string>

namespace fem::fig {

using namespace detail;

struct MeshWindow::Impl {
    vtkNew<vtkRenderWindow> window;
    vtkNew<vtkRenderWindowInteractor> interactor;
    vtkNew<vtkCallbackCommand> on_key;
    std::string keys;  // pressed since the last poll
};

MeshWindow::MeshWindow(const RenderOptions& options, const std::string& window_name) : impl_(std::make_unique<Impl>())
{
    if (!display_available())
        throw Error("no X display for a window (set DISPLAY, or run under xvfb-run -a)");
    impl_->window->SetDisplayId(shared_display());
    impl_->window->SetSize(options.width * options.scale, options.height * options.scale);
    impl_->window->SetWindowName(window_name.c_str());
    impl_->interactor->SetRenderWindow(impl_->window);
    impl_->interactor->SetInteractorStyle(nullptr);  // the camera stays the PNGs' one
    impl_->on_key->SetClientData(impl_.get());
    impl_->on_key->SetCallback([](vtkObject* caller, unsigned long, void* client, void*) {
        auto* interactor = static_cast<vtkRenderWindowInteractor*>(caller);
        const std::string key = interactor->GetKeySym() ? interactor->GetKeySym() : "";
        static_cast<Impl*>(client)->keys += key == "space" ? ' ' : key == "Right" ? '>' : key.size() == 1 ? key[0] : '\0';
    });
    impl_->interactor->AddObserver(vtkCommand::KeyPressEvent, impl_->on_key);
    impl_->interactor->Initialize();
}

MeshWindow::~MeshWindow() = default;

void MeshWindow::show(const io::MeshData& mesh, const RenderOptions& options)
{
    const auto [grid, cell_field] = drawable(mesh, options);
    impl_->window->GetRenderers()->RemoveAllItems();
    render_with_labels(impl_->window, add_renderers(impl_->window, grid, cell_field, true, options));
}

std::string MeshWindow::poll_keys()
{
    impl_->interactor->ProcessEvents();
    std::string keys;
    keys.swap(impl_->keys);
    keys.erase(std::remove(keys.begin(), keys.end(), '\0'), keys.end());
    return keys;
}

void MeshWindow::save_png(const std::filesystem::path& path)
{
    write_png(impl_->window, path);
}

}  // namespace fem::fig
