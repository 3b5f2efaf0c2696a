// Figures: the on-screen window (MeshWindow) that shows a mesh frame by frame, drawn by the same
// renderers as the PNGs of figures_mesh.cpp, and reports the keys pressed and the mesh point the
// mouse drags (the scenes' --view).
#include "common/figures.hpp"

#include "common/error.hpp"
#include "common/figures_internal.hpp"

#include <vtkCallbackCommand.h>
#include <vtkNew.h>
#include <vtkRenderer.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRendererCollection.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace fem::fig {

using namespace detail;

struct MeshWindow::Impl {
    vtkNew<vtkRenderWindow> window;
    vtkNew<vtkRenderWindowInteractor> interactor;
    vtkNew<vtkCallbackCommand> on_key, on_press, on_move, on_release;
    std::string keys;  // pressed since the last poll
    MatrixX3d points;  // the mesh last shown
    vtkSmartPointer<vtkRenderer> data;  // its renderer
    double radius = pick_radius;
    PointerDrag drag;
    double depth = 0.0;  // the picked point's display depth

    /// The display coordinates (x, y in pixels, z the depth in [0, 1]) of a world point.
    Eigen::Vector3d to_display(const Eigen::Vector3d& world) const
    {
        data->SetWorldPoint(world.x(), world.y(), world.z(), 1.0);
        data->WorldToDisplay();
        Eigen::Vector3d display;
        data->GetDisplayPoint(display.data());
        return display;
    }
    /// The world point at display pixel (x, y) and depth z.
    Eigen::Vector3d to_world(double x, double y, double z) const
    {
        data->SetDisplayPoint(x, y, z);
        data->DisplayToWorld();
        double world[4];
        data->GetWorldPoint(world);
        return Eigen::Vector3d(world[0], world[1], world[2]) / world[3];
    }
    /// The left button went down at pixel (x, y): picks the point nearest the camera among those
    /// within radius pixels, if any.
    void press(double x, double y)
    {
        if (data == nullptr)
            return;
        double nearest = std::numeric_limits<double>::infinity();
        for (Eigen::Index i = 0; i < points.rows(); ++i) {
            const Eigen::Vector3d d = to_display(points.row(i).transpose());
            if (std::hypot(d.x() - x, d.y() - y) <= radius && d.z() < nearest) {
                nearest = d.z();
                drag.point = static_cast<int>(i);
                drag.target = points.row(i).transpose();
                depth = d.z();
            }
        }
    }
    void move(double x, double y)
    {
        if (drag.point >= 0)
            drag.target = to_world(x, y, depth);
    }
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
    impl_->radius = pick_radius * options.scale;
    impl_->on_press->SetClientData(impl_.get());
    impl_->on_press->SetCallback([](vtkObject* caller, unsigned long, void* client, void*) {
        const int* at = static_cast<vtkRenderWindowInteractor*>(caller)->GetEventPosition();
        static_cast<Impl*>(client)->press(at[0], at[1]);
    });
    impl_->on_move->SetClientData(impl_.get());
    impl_->on_move->SetCallback([](vtkObject* caller, unsigned long, void* client, void*) {
        const int* at = static_cast<vtkRenderWindowInteractor*>(caller)->GetEventPosition();
        static_cast<Impl*>(client)->move(at[0], at[1]);
    });
    impl_->on_release->SetClientData(impl_.get());
    impl_->on_release->SetCallback([](vtkObject*, unsigned long, void* client, void*) {
        static_cast<Impl*>(client)->drag = {};
    });
    impl_->interactor->AddObserver(vtkCommand::LeftButtonPressEvent, impl_->on_press);
    impl_->interactor->AddObserver(vtkCommand::MouseMoveEvent, impl_->on_move);
    impl_->interactor->AddObserver(vtkCommand::LeftButtonReleaseEvent, impl_->on_release);
    impl_->interactor->Initialize();
}

MeshWindow::~MeshWindow() = default;

void MeshWindow::show(const io::MeshData& mesh, const RenderOptions& options)
{
    const auto [grid, cell_field] = drawable(mesh, options);
    impl_->window->GetRenderers()->RemoveAllItems();
    const BarLabels labels = add_renderers(impl_->window, grid, cell_field, true, options);
    impl_->data = labels.data;
    impl_->points = mesh.points;
    render_with_labels(impl_->window, labels);
}

std::string MeshWindow::poll_keys()
{
    impl_->interactor->ProcessEvents();
    std::string keys;
    keys.swap(impl_->keys);
    keys.erase(std::remove(keys.begin(), keys.end(), '\0'), keys.end());
    return keys;
}

void MeshWindow::set_name(const std::string& name)
{
    impl_->window->SetWindowName(name.c_str());
}

MeshWindow::PointerDrag MeshWindow::pointer_drag() const
{
    return impl_->drag;
}

void MeshWindow::save_png(const std::filesystem::path& path)
{
    write_png(impl_->window, path);
}

}  // namespace fem::fig
